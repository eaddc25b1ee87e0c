#include "collision/colliders.hpp"

#include "collision/broad_phase.hpp"
#include "integrators/fast_solver.hpp"
#include "integrators/work_team.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>
#include <utility>

namespace clothsim {
namespace {

// Returns a bound on how far it moved any particle: each push is at most depth (1 + friction) long (the normal
// push plus a friction cut of at most friction x depth), or the way back to where a swept path entered. A NaN
// position has NaN depth and is left alone (the guard reports it).
//
// A moving collider (`surface` not null, collider_motion.hpp) works on the motion relative to its surface: the
// particle's motion less the surface's displacement where it ends, and gives the surface's displacement back
// with what is left of it.
template <class T, class Shape>
T collide_shape(State& state, const Shape& shape, T friction, T thickness, std::size_t begin,
                std::size_t end, const SurfaceMotion* surface = nullptr) {
    using Vec = glm::vec<3, T>;
    T deepest = T(0);
    for (std::size_t i = begin; i < end; ++i) {
        if (state.pinned[i]) continue;
        const Contact<T> c = contact(shape, state.position.get(i), thickness);
        const Vec carried = surface ? Vec(surface->displacement(state.position.get(i))) : Vec(T(0));
        const Vec motion = surface ? state.motion.get(i) - carried : state.motion.get(i);
        // A large step can end outside after passing through (no contact at the end), or inside past the
        // middle, where the nearest way out points along the motion and leads out of the far side. Then the
        // particle stops where its path (x - motion -> x: the motion is the substep's displacement for every
        // integrator) entered the shell, the inward part of its motion removed as in any inelastic contact;
        // no friction on this rare path.
        // Cheap filters first: outside, the path must be long enough to reach the solid (the shell's
        // distance, as far as `contact` knows it, plus the thickness); inside, moving outward, it must be longer than the depth (it may have
        // come in from the other side).
        const T reach = thickness - std::min(c.depth, T(0));
        const bool may_have_passed = c.depth > T(0)
                                         ? glm::dot(c.normal, motion) > T(0) && glm::dot(motion, motion) > c.depth * c.depth
                                         : glm::dot(motion, motion) > reach * reach;
        if (may_have_passed) {
            const Vec p1 = state.position.get(i), p0 = p1 - motion;
            const auto hit = !sweeps_from_shell(shape) && contact(shape, p0, thickness).depth > T(0)
                                 ? std::nullopt
                                 : swept_hit(shape, p0, p1, thickness);
            if (hit) {
                const Vec entry = p0 + hit->t * motion;
                deepest = std::max(deepest, glm::length(p1 - entry));
                state.position.set(i, entry);
                const Vec kept = motion - std::min(glm::dot(motion, hit->normal), T(0)) * hit->normal;
                state.motion.set(i, surface ? kept + Vec(surface->displacement(entry)) : kept);
                continue;
            }
        }
        if (!(c.depth > T(0))) continue;
        deepest = std::max(deepest, c.depth);
        const T normal_motion = glm::dot(motion, c.normal);
        const Vec tangential = motion - normal_motion * c.normal;
        // Coulomb: the tangential motion loses at most mu times the normal push (static when it is less).
        const T slide = glm::length(tangential);
        const Vec friction_cut = slide > T(0) ? -tangential * (std::min(slide, friction * c.depth) / slide) : Vec(T(0));
        state.position.add(i, c.normal * c.depth + friction_cut);
        // Inelastic contact: the push moves the particle out but does not launch it. Keeping the push in
        // the motion (x_prev left in place, as plain Verlet projection does) turns a deep penetration into a
        // velocity of depth / h: a cloth started half inside the sphere exploded that way.
        const Vec kept = tangential + friction_cut + std::max(normal_motion, T(0)) * c.normal;
        state.motion.set(i, surface ? kept + carried : kept);
    }
    return std::max(deepest * (T(1) + friction), deepest);
}

// A block of kBlockParticles particles against a sphere, as collide_shape does it with the same arithmetic
// in the same order, four particles at a time with AVX2 (collide_shape's branches on contact mispredict at
// the rim of a drape, and its square roots and divides wait on each other; GCC leaves this loop scalar). A
// particle whose path may have passed through the sphere is only flagged here and then taken by
// collide_shape itself; the caller sends a block holding a pinned particle to collide_shape. Returns
// collide_shape's bound on the push.
__attribute__((target("avx2,fma"))) inline __m256d lanes_add(__m256d a, __m256d b) { return _mm256_add_pd(a, b); }
__attribute__((target("avx2,fma"))) inline __m256d lanes_sub(__m256d a, __m256d b) { return _mm256_sub_pd(a, b); }
__attribute__((target("avx2,fma"))) inline __m256d lanes_mul(__m256d a, __m256d b) { return _mm256_mul_pd(a, b); }
__attribute__((target("avx2,fma"))) inline __m256d lanes_less(__m256d a, __m256d b) { return _mm256_cmp_pd(a, b, _CMP_LT_OQ); }
__attribute__((target("avx2,fma"))) inline __m256d lanes_dot(__m256d ax, __m256d ay, __m256d az, __m256d bx, __m256d by,
                                                       __m256d bz) {
    return lanes_add(lanes_add(lanes_mul(ax, bx), lanes_mul(ay, by)), lanes_mul(az, bz));  // glm::dot's order
}
__attribute__((target("avx2,fma"))) double collide_sphere_block_avx2(State& state, const SphereCollider& sphere,
                                                                     double friction, double thickness,
                                                                     std::size_t begin) {
    double* px = state.position.x.data() + begin;
    double* py = state.position.y.data() + begin;
    double* pz = state.position.z.data() + begin;
    double* mx = state.motion.x.data() + begin;
    double* my = state.motion.y.data() + begin;
    double* mz = state.motion.z.data() + begin;
    const double reach_s = double(sphere.radius) + thickness;
    const __m256d cx = _mm256_set1_pd(sphere.center.x), cy = _mm256_set1_pd(sphere.center.y),
                  cz = _mm256_set1_pd(sphere.center.z), reach = _mm256_set1_pd(reach_s),
                  far2 = _mm256_set1_pd(reach_s * reach_s * 1.00001),  // contact()'s test for clearly outside
        tiny = _mm256_set1_pd(double(1e-12f)), zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0),
                  sign = _mm256_set1_pd(-0.0), shell_width = _mm256_set1_pd(thickness), mu = _mm256_set1_pd(friction);
    __m256d deepest = zero;
    unsigned slow = 0;  // bit k: particle begin + k may have passed through
    static_assert(kBlockParticles % 4 == 0);
    for (std::size_t k = 0; k < kBlockParticles; k += 4) {
        const __m256d x = _mm256_loadu_pd(px + k), y = _mm256_loadu_pd(py + k), z = _mm256_loadu_pd(pz + k);
        const __m256d vx = _mm256_loadu_pd(mx + k), vy = _mm256_loadu_pd(my + k), vz = _mm256_loadu_pd(mz + k);
        // contact(): the normal (0, 1, 0) and depth 0 when clearly outside or without a direction.
        const __m256d dx = lanes_sub(x, cx), dy = lanes_sub(y, cy), dz = lanes_sub(z, cz);
        const __m256d dd = lanes_dot(dx, dy, dz, dx, dy, dz);
        const __m256d far = _mm256_cmp_pd(dd, far2, _CMP_GT_OQ);
        const __m256d length = _mm256_sqrt_pd(dd);
        const __m256d direction = _mm256_andnot_pd(far, _mm256_cmp_pd(length, tiny, _CMP_GT_OQ));
        const __m256d nx = _mm256_and_pd(direction, _mm256_div_pd(dx, length));
        const __m256d ny = _mm256_blendv_pd(one, _mm256_div_pd(dy, length), direction);
        const __m256d nz = _mm256_and_pd(direction, _mm256_div_pd(dz, length));
        const __m256d depth = _mm256_andnot_pd(far, lanes_sub(reach, length));
        // may_have_passed, as collide_shape tests it.
        const __m256d vv = lanes_dot(vx, vy, vz, vx, vy, vz);
        const __m256d normal_motion = lanes_dot(nx, ny, nz, vx, vy, vz);
        const __m256d shell = lanes_sub(shell_width, _mm256_blendv_pd(depth, zero, lanes_less(zero, depth)));  // std::min(depth, 0)
        const __m256d contact = _mm256_cmp_pd(depth, zero, _CMP_GT_OQ);
        const __m256d may_have_passed = _mm256_blendv_pd(
            _mm256_cmp_pd(vv, lanes_mul(shell, shell), _CMP_GT_OQ),
            _mm256_and_pd(_mm256_cmp_pd(normal_motion, zero, _CMP_GT_OQ), _mm256_cmp_pd(vv, lanes_mul(depth, depth), _CMP_GT_OQ)),
            contact);
        slow |= static_cast<unsigned>(_mm256_movemask_pd(may_have_passed)) << k;
        const __m256d push = _mm256_andnot_pd(may_have_passed, contact);
        // The push out and the Coulomb friction cut.
        const __m256d tx = lanes_sub(vx, lanes_mul(normal_motion, nx)), ty = lanes_sub(vy, lanes_mul(normal_motion, ny)),
                      tz = lanes_sub(vz, lanes_mul(normal_motion, nz));
        const __m256d slide = _mm256_sqrt_pd(lanes_dot(tx, ty, tz, tx, ty, tz));
        const __m256d most = lanes_mul(mu, depth);
        const __m256d cut = _mm256_div_pd(_mm256_blendv_pd(slide, most, lanes_less(most, slide)), slide);  // std::min(slide, most)
        const __m256d sliding = _mm256_cmp_pd(slide, zero, _CMP_GT_OQ);
        const __m256d fx = _mm256_and_pd(sliding, lanes_mul(_mm256_xor_pd(tx, sign), cut));
        const __m256d fy = _mm256_and_pd(sliding, lanes_mul(_mm256_xor_pd(ty, sign), cut));
        const __m256d fz = _mm256_and_pd(sliding, lanes_mul(_mm256_xor_pd(tz, sign), cut));
        const __m256d out = _mm256_blendv_pd(normal_motion, zero, lanes_less(normal_motion, zero));  // std::max(normal_motion, 0)
        _mm256_storeu_pd(px + k, _mm256_blendv_pd(x, lanes_add(x, lanes_add(lanes_mul(nx, depth), fx)), push));
        _mm256_storeu_pd(py + k, _mm256_blendv_pd(y, lanes_add(y, lanes_add(lanes_mul(ny, depth), fy)), push));
        _mm256_storeu_pd(pz + k, _mm256_blendv_pd(z, lanes_add(z, lanes_add(lanes_mul(nz, depth), fz)), push));
        _mm256_storeu_pd(mx + k, _mm256_blendv_pd(vx, lanes_add(lanes_add(tx, fx), lanes_mul(out, nx)), push));
        _mm256_storeu_pd(my + k, _mm256_blendv_pd(vy, lanes_add(lanes_add(ty, fy), lanes_mul(out, ny)), push));
        _mm256_storeu_pd(mz + k, _mm256_blendv_pd(vz, lanes_add(lanes_add(tz, fz), lanes_mul(out, nz)), push));
        deepest = _mm256_blendv_pd(deepest, depth, _mm256_and_pd(push, lanes_less(deepest, depth)));
    }
    const __m128d half = _mm_max_pd(_mm256_castpd256_pd128(deepest), _mm256_extractf128_pd(deepest, 1));
    const double most_pushed = std::max(_mm_cvtsd_f64(half), _mm_cvtsd_f64(_mm_unpackhi_pd(half, half)));
    double bound = std::max(most_pushed * (1.0 + friction), most_pushed);
    for (std::size_t k = 0; k < kBlockParticles; ++k) {
        if (slow >> k & 1u) {
            bound = std::max(bound, collide_shape(state, sphere, friction, thickness, begin + k, begin + k + 1));
        }
    }
    return bound;
}

// Returns the number of blocks tested: none, and no particle moved.
template <class Shape>
long long collide_blocks(State& state, const Shape& shape, float friction, float thickness, bool broad_phase,
                         CollisionBlocks& blocks, const Box& cloth, std::size_t kind, int threads, StepProfile* profile,
                         const SurfaceMotion* surface) {
    // First the whole cloth (`cloth` holds it): a collider out of its reach costs this one test; then each
    // block's box. `at`: the shape as its queries take it (shape.hpp: placed). A moving collider's relative
    // paths start up to its surface's largest displacement outside the swept boxes: the test reaches that much
    // farther.
    decltype(auto) at = placed(shape, thickness);
    const float reach = surface ? static_cast<float>(thickness + surface->reach) : thickness;
    const bool whole_cloth = !broad_phase || may_touch(at, reach, cloth);
    blocks.tested.clear();
    std::size_t particles = 0;
    for (std::size_t k = 0; whole_cloth && k < blocks.count(); ++k) {
        if (broad_phase && !may_touch(at, reach, blocks.boxes[k])) continue;
        blocks.tested.push_back(static_cast<std::uint32_t>(k));
        particles += blocks.start[k + 1] - blocks.start[k];
    }
    const auto tested = static_cast<long long>(blocks.tested.size());
    blocks.grown.assign(blocks.tested.size(), 0);
    // Blocks hold distinct particles: threads share them when there are enough to pay for the fork (four
    // times as many for the ground, whose test is a comparison), and the result is the same for any count.
    const std::size_t enough = Shape::kHalfSpace ? 4 * kParallelCollisionParticles : kParallelCollisionParticles;
    const int team = threads > 1 && particles >= enough ? threads : 1;
    auto test = [&](long long t) {
        const std::size_t k = blocks.tested[t];
        const std::size_t begin = blocks.start[k], end = blocks.start[k + 1];
        double bound = 0.0;
        if constexpr (std::is_same_v<Shape, SphereCollider>) {
            if (!surface && FastSolver::kernel() != FastKernel::Generic && end - begin == kBlockParticles &&
                std::none_of(state.pinned.begin() + begin, state.pinned.begin() + end, [](std::uint8_t p) { return p != 0; })) {
                bound = collide_sphere_block_avx2(state, at, double(friction), double(thickness), begin);
            } else {
                bound = collide_shape(state, at, double(friction), double(thickness), begin, end, surface);
            }
        } else {
            bound = collide_shape(state, at, double(friction), double(thickness), begin, end, surface);
        }
        const float moved = static_cast<float>(bound);
        if (moved > 0.0f && broad_phase) {
            // Grow the box by the farthest push (and a rounding margin) instead of recomputing it: still
            // conservative for the next collider, and O(1).
            Box& box = blocks.boxes[k];
            const glm::vec3 far = glm::max(glm::abs(box.lo), glm::abs(box.hi));
            const glm::vec3 grow(moved * (1.0f + 1e-5f) + 1e-6f * (1.0f + std::max({far.x, far.y, far.z})));
            box.lo -= grow;
            box.hi += grow;
            blocks.grown[t] = 1;
        }
    };
    // Pieces of 16 blocks for the team (work_team.hpp); one thread runs them in order.
    constexpr long long kPiece = 16;
    WorkTeam::shared().run(team, static_cast<int>((tested + kPiece - 1) / kPiece), [&](int piece, int) {
        for (long long t = piece * kPiece, end = std::min(tested, t + kPiece); t < end; ++t) test(t);
    });
    for (long long t = 0; t < tested; ++t) {
        if (!blocks.grown[t]) continue;
        const Box& box = blocks.boxes[blocks.tested[t]];
        blocks.cloth.lo = glm::min(blocks.cloth.lo, box.lo);  // grows only: stays conservative
        blocks.cloth.hi = glm::max(blocks.cloth.hi, box.hi);
    }
    if (profile) {
        profile->blocks_tested[kind] += tested;
        profile->blocks_offered[kind] += static_cast<long long>(blocks.count());
    }
    return tested;
}

}  // namespace

void collide_all(State& state, const ColliderSettings& colliders, std::size_t begin, std::size_t end) {
    end = std::min(end, state.size());
    for (const Collider& c : colliders.shapes) {
        if (c.enabled) collide(state, c, colliders.thickness, begin, end);
    }
}

void collide(State& state, const Collider& collider, float thickness, std::size_t begin, std::size_t end) {
    std::visit([&](const auto& shape) {
        collide_shape(state, placed(shape, thickness), double(collider.friction), double(thickness), begin, std::min(end, state.size()));
    }, collider.shape);
}

std::size_t push_out_of_mesh(State& state, const Collider& collider, float thickness) {
    const auto* shape = std::get_if<MeshCollider>(&collider.shape);
    if (!collider.enabled || !shape || !shape->mesh || !shape->mesh->closed() || !(shape->scale > 0.0f) ||
        !(thickness > 0.0f)) {
        return 0;
    }
    const PlacedMesh at = placed(*shape, thickness);
    const TriangleMesh& mesh = *at.mesh;
    const ContactGrid& grid = *at.grid;
    const double shell = static_cast<double>(thickness) / at.scale;
    std::size_t moved = 0;
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) continue;
        const glm::dvec3 q = at.to_mesh(state.position.get(i));
        if (q.x < mesh.lo().x || q.x > mesh.hi().x || q.y < mesh.lo().y || q.y > mesh.hi().y || q.z < mesh.lo().z ||
            q.z > mesh.hi().z) {
            continue;  // outside the mesh's box (a NaN too)
        }
        // Within the shell: the contact's; in a cell that lists no triangle: the cell says; else the tree.
        if (mesh.nearest(q, shell, grid)) continue;
        const std::size_t cell = grid.cell_of(q);
        if (cell != ContactGrid::kNone && grid.start[cell + 1] == grid.start[cell] && !grid.inside[cell]) continue;
        const auto near = mesh.nearest(q, INFINITY);
        if (!near || !near->inside) continue;
        // Out along the way to the nearest point, and the thickness past it.
        const glm::dvec3 out = near->distance > 0.0 ? (near->point - q) / near->distance : near->normal;
        const glm::dvec3 normal = at.rotation * out;
        state.position.set(i, at.to_world(near->point + shell * out));
        const glm::dvec3 motion = state.motion.get(i);
        state.motion.set(i, motion - std::min(glm::dot(motion, normal), 0.0) * normal);
        ++moved;
    }
    return moved;
}

namespace {

// Whether a solid shape (not a half-space) that is enabled may touch a particle in `box`.
bool solids_may_touch(const ColliderSettings& colliders, const Box& box) {
    return std::any_of(colliders.shapes.begin(), colliders.shapes.end(), [&](const Collider& c) {
        return c.enabled && !is_half_space(c) && may_touch(c, colliders.thickness, box);
    });
}

bool any_solid(const ColliderSettings& colliders) {
    return std::any_of(colliders.shapes.begin(), colliders.shapes.end(),
                       [](const Collider& c) { return c.enabled && !is_half_space(c); });
}

bool any_moving_solid(const ColliderSettings& colliders) {
    return std::any_of(colliders.shapes.begin(), colliders.shapes.end(),
                       [](const Collider& c) { return c.enabled && !is_half_space(c) && c.motion.moves(); });
}

bool any_half_space(const ColliderSettings& colliders) {
    return std::any_of(colliders.shapes.begin(), colliders.shapes.end(),
                       [](const Collider& c) { return c.enabled && is_half_space(c); });
}

}  // namespace

BlockBounds block_bounds_for(const ColliderSettings& colliders, const CollisionBlocks& blocks) {
    if (!any_solid(colliders)) return BlockBounds::Lowest;
    // The carried box is tested against where the solids are now; a moving one is somewhere else next substep.
    if (any_moving_solid(colliders)) return BlockBounds::Box;
    return blocks.carried_valid && !solids_may_touch(colliders, blocks.carried()) ? BlockBounds::Lowest
                                                                                   : BlockBounds::Box;
}

bool collide_stage(State& state, const ColliderSettings& colliders, bool broad_phase, CollisionBlocks& blocks,
                   StepProfile* profile, int threads, const MotionBounds* motion, const SurfaceMotion* surfaces) {
    if (blocks.start.empty() || blocks.start.back() != state.size()) {
        blocks.start = block_starts(state.size(), 0, 0);
        blocks.current = blocks.boxes_current = false;
    }
    const std::size_t count = blocks.count();
    const bool shapes = any_solid(colliders);
    if (!shapes) blocks.carried_valid = false;  // grown only while a solid shape may need it
    if (!shapes && !any_half_space(colliders)) return false;
    const auto finite = [](glm::dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    const bool known = motion && !motion->empty && finite(motion->lo) && finite(motion->hi);
    if (!broad_phase) {
        blocks.boxes.resize(count);  // only counted: every block is tested
        blocks.current = blocks.boxes_current = blocks.carried_valid = false;
    } else if (!(blocks.current && blocks.boxes.size() == count)) {
        StageTimer timer(profile, Stage::BroadPhase);
        bool from_sweep = blocks.boxes_current && blocks.boxes.size() == count;
        if (!from_sweep) blocks.bounds = BlockBounds::Box;
        if (blocks.bounds == BlockBounds::Lowest && shapes && any_moving_solid(colliders)) from_sweep = false;
        if (!from_sweep) blocks.bounds = BlockBounds::Box;
        if (blocks.bounds == BlockBounds::Lowest && shapes) {
            // Lowest points only: the sphere, the cube and the cylinder test the carried box, grown by this
            // substep's motion; whole boxes are made here when it may reach one of them or cannot be grown.
            if (motion) {
                blocks.carried_valid = blocks.carried_valid && known;
                if (blocks.carried_valid) {
                    blocks.carried_lo += glm::min(motion->lo, glm::dvec3(0.0));
                    blocks.carried_hi += glm::max(motion->hi, glm::dvec3(0.0));
                }
            }
            if (!blocks.carried_valid || solids_may_touch(colliders, blocks.carried())) {
                from_sweep = false;
                blocks.bounds = BlockBounds::Box;
            }
        }
        blocks.boxes.resize(count);
        // Swept boxes: grown by the cloth's largest motion per axis, they also hold where the substep started
        // (x - motion), so a particle that passed through the sphere, the cube or the cylinder in one substep is still
        // offered to it (continuous collision). One bound for the cloth costs one vectorised pass, not one
        // per block; the ground (a half-space: nothing passes through it unseen) needs none.
        // The caller's bounds (NaN motions left out, as the pass leaves them), rounded to float as
        // particle_bounds rounds them, give the same reach; bounds that are not finite (no motion that is a
        // number, or an infinite one) are taken again by the pass.
        glm::vec3 reach(0.0f);
        if (shapes && blocks.bounds == BlockBounds::Box) {
            const Box bounds = known ? Box{glm::vec3(motion->lo), glm::vec3(motion->hi)}
                                     : particle_bounds(state.motion, 0, state.size());
            if (!bounds.empty()) reach = glm::max(glm::abs(bounds.lo), glm::abs(bounds.hi));
        }
        if (!from_sweep || reach != glm::vec3(0.0f)) {
            auto box_range = [&](std::size_t first, std::size_t last) {
                for (std::size_t k = first; k < last; ++k) {
                    Box& box = blocks.boxes[k];
                    if (!from_sweep) box = particle_bounds(state.position, blocks.start[k], blocks.start[k + 1]);
                    box.lo -= reach;
                    box.hi += reach;
                }
            };
            // On the team in pieces of 64 blocks (a mesh cloth's: the grid's are boxed in the fast solver's
            // bands): 1024 particles, the pieces of the mesh's other stages, so each thread boxes the particles
            // it has just moved. Each box is its block's alone: the same boxes on any number of threads.
            constexpr std::size_t kPieceBlocks = 64;
            if (threads > 1 && WorkTeam::pieces(count, kPieceBlocks) > 1) {
                WorkTeam::shared().run_pieces(threads, count, kPieceBlocks, box_range);
            } else {
                box_range(0, count);
            }
        }
        // Boxes as the bands made them, with nothing added: the union of the bands' unions is theirs.
        const bool unions = from_sweep && reach == glm::vec3(0.0f) && blocks.band_unions;
        blocks.cloth = unions ? union_of(blocks.band_union.data(), blocks.band_union.size()) : union_of(blocks.boxes.data(), count);
        blocks.band_unions = false;
        blocks.boxes_current = blocks.current = true;
    }
    const float thickness = colliders.thickness;
    long long tested = 0;
    // With Lowest boxes the shapes meet only the carried box, which none of them can reach (checked above).
    const Box shape_cloth = blocks.bounds == BlockBounds::Lowest ? blocks.carried() : blocks.cloth;
    {
        StageTimer timer(profile, Stage::Colliders);
        for (std::size_t i = 0; i < colliders.shapes.size(); ++i) {
            const Collider& c = colliders.shapes[i];
            if (!c.enabled) continue;
            // A half-space reads the blocks' lowest points, which every box holds.
            const Box& cloth = is_half_space(c) ? blocks.cloth : shape_cloth;
            const SurfaceMotion* surface = surfaces && c.motion.moves() ? &surfaces[i] : nullptr;
            tested += std::visit([&](const auto& shape) {
                return collide_blocks(state, shape, c.friction, thickness, broad_phase, blocks, cloth, c.kind(), threads,
                                      profile, surface);
            }, c.shape);
        }
    }
    // Whole boxes (grown by any push) hold every particle: the carried box starts again from them. A push
    // under Lowest boxes may leave the carried box.
    if (broad_phase && blocks.bounds == BlockBounds::Box) {
        blocks.carried_valid = !blocks.cloth.empty() && finite(glm::dvec3(blocks.cloth.lo)) &&
                               finite(glm::dvec3(blocks.cloth.hi));
        blocks.carried_lo = glm::dvec3(blocks.cloth.lo);
        blocks.carried_hi = glm::dvec3(blocks.cloth.hi);
    } else if (tested > 0) {
        blocks.carried_valid = false;
    }
    return tested > 0;
}

}  // namespace clothsim
