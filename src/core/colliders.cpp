#include "clothsim/colliders.hpp"

#include "contact_geometry.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>
#include <utility>

namespace clothsim {
namespace {

// Continuous collision: where the straight path p0 -> p1 of a substep passed through the solid shape
// (the sphere of radius r, the box itself, not the thickness shell around them) although both ends are
// outside. A path that only grazes the shell (a particle sliding over the surface cuts a chord into it) is
// not a pass. `t` is where the path enters the shell (radius r + thickness, the box grown by thickness) and
// `normal` the shell's outward normal there.
template <class T>
struct SweptHit {
    T t = T(0);
    glm::vec<3, T> normal{T(0), T(1), T(0)};
};

// Smallest t in [0, 1] with |p0 + t d - c| = radius, if the segment reaches that sphere.
template <class T>
std::optional<T> enter_sphere(glm::vec<3, T> f, glm::vec<3, T> d, T radius) {
    const T a = glm::dot(d, d);
    if (!(a > T(0))) return std::nullopt;
    const T b = glm::dot(f, d);
    const T disc = b * b - a * (glm::dot(f, f) - radius * radius);
    if (!(disc >= T(0))) return std::nullopt;
    const T t = (-b - std::sqrt(disc)) / a;
    if (!(t <= T(1)) || (-b + std::sqrt(disc)) / a < T(0)) return std::nullopt;
    return std::max(t, T(0));
}

template <class T>
std::optional<SweptHit<T>> swept_hit(const SphereCollider& sphere, glm::vec<3, T> p0, glm::vec<3, T> p1, T thickness) {
    const glm::vec<3, T> f = p0 - glm::vec<3, T>(sphere.center), d = p1 - p0;
    if (!enter_sphere(f, d, T(sphere.radius))) return std::nullopt;
    SweptHit<T> hit;
    hit.t = enter_sphere(f, d, T(sphere.radius) + thickness).value_or(T(0));
    const glm::vec<3, T> at = f + hit.t * d;
    const T length = glm::length(at);
    if (length > T(1e-12f)) hit.normal = at / length;
    return hit;
}

// Slab test against the box grown by `grow`: the entry t and the axis it enters through.
template <class T>
std::optional<std::pair<T, int>> enter_box(const CubeCollider& cube, glm::vec<3, T> p0, glm::vec<3, T> d, T grow) {
    T near = T(0), far = T(1);
    int axis = -1;
    for (int a = 0; a < 3; ++a) {
        const T lo = T(cube.center[a]) - T(0.5) * T(cube.size[a]) - grow;
        const T hi = T(cube.center[a]) + T(0.5) * T(cube.size[a]) + grow;
        if (d[a] == T(0)) {
            if (p0[a] < lo || p0[a] > hi) return std::nullopt;
            continue;
        }
        T t0 = (lo - p0[a]) / d[a], t1 = (hi - p0[a]) / d[a];
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > near) {
            near = t0;
            axis = a;
        }
        far = std::min(far, t1);
        if (!(near <= far)) return std::nullopt;
    }
    return std::pair<T, int>(near, axis);
}

template <class T>
std::optional<SweptHit<T>> swept_hit(const CubeCollider& cube, glm::vec<3, T> p0, glm::vec<3, T> p1, T thickness) {
    const glm::vec<3, T> d = p1 - p0;
    if (!enter_box(cube, p0, d, T(0))) return std::nullopt;
    const auto entry = enter_box(cube, p0, d, thickness);
    SweptHit<T> hit;
    if (!entry || entry->second < 0) return std::nullopt;  // started inside the shell: the depth test's case
    hit.t = entry->first;
    hit.normal = glm::vec<3, T>(T(0));
    hit.normal[entry->second] = d[entry->second] > T(0) ? T(-1) : T(1);
    return hit;
}

// The segment p0 -> p0 + d (p0 relative to the centre) against the cylinder grown by `grow` (radius + grow,
// each face moved out by grow: flat, like the box's): the entry t and the surface it enters through, 0 a face,
// 1 the side, -1 none (it starts inside). The intersection of the slab between the faces with the infinite
// cylinder around the axis, each an interval of t.
template <class T>
std::optional<std::pair<T, int>> enter_cylinder(const CylinderCollider& cylinder, glm::vec<3, T> p0,
                                                glm::vec<3, T> d, T grow) {
    T near = T(0), far = T(1);
    int surface = -1;
    const T half = T(0.5) * T(cylinder.height) + grow;
    if (d.y == T(0)) {
        if (std::abs(p0.y) > half) return std::nullopt;
    } else {
        T t0 = (-half - p0.y) / d.y, t1 = (half - p0.y) / d.y;
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > near) {
            near = t0;
            surface = 0;
        }
        far = std::min(far, t1);
    }
    const T radius = T(cylinder.radius) + grow;
    const T a = d.x * d.x + d.z * d.z;
    const T c = p0.x * p0.x + p0.z * p0.z - radius * radius;
    if (!(a > T(0))) {
        if (c > T(0)) return std::nullopt;  // moving along the axis, beside the cylinder
    } else {
        const T b = p0.x * d.x + p0.z * d.z;
        const T disc = b * b - a * c;
        if (!(disc >= T(0))) return std::nullopt;
        const T root = std::sqrt(disc);
        const T t0 = (-b - root) / a, t1 = (-b + root) / a;
        if (t0 > near) {
            near = t0;
            surface = 1;
        }
        far = std::min(far, t1);
    }
    if (!(near <= far)) return std::nullopt;
    return std::pair<T, int>(near, surface);
}

template <class T>
std::optional<SweptHit<T>> swept_hit(const CylinderCollider& cylinder, glm::vec<3, T> p0, glm::vec<3, T> p1,
                                     T thickness) {
    using Vec = glm::vec<3, T>;
    const Vec f = p0 - Vec(cylinder.center), d = p1 - p0;
    if (!enter_cylinder(cylinder, f, d, T(0))) return std::nullopt;
    const auto entry = enter_cylinder(cylinder, f, d, thickness);
    if (!entry) return std::nullopt;
    SweptHit<T> hit;
    if (entry->second < 0) {
        // Starts inside the flat-grown cylinder but outside the shell (collide_shape checked): beside a rim,
        // where the shell is rounded. It stops where it is, its motion toward the rim removed.
        hit.t = T(0);
        hit.normal = contact(cylinder, p0, thickness).normal;
        return hit;
    }
    hit.t = entry->first;
    if (entry->second == 0) {
        hit.normal = Vec(T(0), d.y > T(0) ? T(-1) : T(1), T(0));
    } else {
        const Vec at = f + hit.t * d;
        const T r = std::sqrt(at.x * at.x + at.z * at.z);
        hit.normal = r > T(1e-12f) ? Vec(at.x / r, T(0), at.z / r) : Vec(T(1), T(0), T(0));
    }
    return hit;
}

// The ground is a half-space: a path that ends below it ends in contact, so there is nothing to sweep.
template <class T>
std::optional<SweptHit<T>> swept_hit(const GroundCollider&, glm::vec<3, T>, glm::vec<3, T>, T) {
    return std::nullopt;
}

// Returns a bound on how far it moved any particle: each push is at most depth (1 + friction) long (the normal
// push plus a friction cut of at most friction x depth), or the way back to where a swept path entered. A NaN
// position has NaN depth and is left alone (the guard reports it).
template <class T, class Shape>
T collide_shape(State& state, const Shape& shape, T friction, T thickness, std::size_t begin,
                std::size_t end) {
    using Vec = glm::vec<3, T>;
    T deepest = T(0);
    for (std::size_t i = begin; i < end; ++i) {
        if (state.pinned[i]) continue;
        const Contact<T> c = contact(shape, state.position.get(i), thickness);
        const Vec motion = state.motion.get(i);
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
            const auto hit = contact(shape, p0, thickness).depth > T(0) ? std::nullopt
                                                                          : swept_hit(shape, p0, p1, thickness);
            if (hit) {
                const Vec entry = p0 + hit->t * motion;
                deepest = std::max(deepest, glm::length(p1 - entry));
                state.position.set(i, entry);
                state.motion.set(i, motion - std::min(glm::dot(motion, hit->normal), T(0)) * hit->normal);
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
        state.motion.set(i, tangential + friction_cut + std::max(normal_motion, T(0)) * c.normal);
    }
    return std::max(deepest * (T(1) + friction), deepest);
}

// Returns the number of blocks tested: none, and no particle moved.
template <class Shape>
long long collide_blocks(State& state, const Shape& shape, float thickness, bool broad_phase, CollisionBlocks& blocks,
                         const Box& cloth, int which, int threads, StepProfile* profile) {
    // First the whole cloth (`cloth` holds it): a collider out of its reach costs this one test; then each
    // block's box.
    const bool whole_cloth = !broad_phase || may_touch(shape, thickness, cloth);
    blocks.tested.clear();
    std::size_t particles = 0;
    for (std::size_t k = 0; whole_cloth && k < blocks.count(); ++k) {
        if (broad_phase && !may_touch(shape, thickness, blocks.boxes[k])) continue;
        blocks.tested.push_back(static_cast<std::uint32_t>(k));
        particles += blocks.start[k + 1] - blocks.start[k];
    }
    const auto tested = static_cast<long long>(blocks.tested.size());
    blocks.grown.assign(blocks.tested.size(), 0);
    // Blocks hold distinct particles: threads share them when there are enough to pay for the fork (four
    // times as many for the ground, whose test is a comparison), and the result is the same for any count.
    const std::size_t enough = std::is_same_v<Shape, GroundCollider> ? 4 * kParallelCollisionParticles
                                                                     : kParallelCollisionParticles;
    const int team = threads > 1 && particles >= enough ? threads : 1;
    auto test = [&](long long t) {
        const std::size_t k = blocks.tested[t];
        const std::size_t begin = blocks.start[k], end = blocks.start[k + 1];
        const float moved = static_cast<float>(collide_shape(state, shape, double(shape.friction), double(thickness), begin, end));
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
    // One thread runs no OpenMP construct at all (libgomp would make a team of one for it every time).
    if (team > 1) {
#pragma omp parallel for num_threads(team) schedule(dynamic, 16)
        for (long long t = 0; t < tested; ++t) test(t);
    } else {
        for (long long t = 0; t < tested; ++t) test(t);
    }
    for (long long t = 0; t < tested; ++t) {
        if (!blocks.grown[t]) continue;
        const Box& box = blocks.boxes[blocks.tested[t]];
        blocks.cloth.lo = glm::min(blocks.cloth.lo, box.lo);  // grows only: stays conservative
        blocks.cloth.hi = glm::max(blocks.cloth.hi, box.hi);
    }
    if (profile) {
        profile->blocks_tested[which] += tested;
        profile->blocks_offered[which] += static_cast<long long>(blocks.count());
    }
    return tested;
}

}  // namespace

float signed_distance(const SphereCollider& sphere, glm::vec3 p) {
    return glm::length(p - sphere.center) - sphere.radius;
}

float signed_distance(const CubeCollider& cube, glm::vec3 p) {
    const glm::vec3 q = glm::abs(p - cube.center) - 0.5f * cube.size;
    return glm::length(glm::max(q, glm::vec3(0.0f))) + std::min(std::max({q.x, q.y, q.z}), 0.0f);
}

float signed_distance(const CylinderCollider& cylinder, glm::vec3 p) {
    const glm::vec3 local = p - cylinder.center;
    const glm::vec2 q(std::sqrt(local.x * local.x + local.z * local.z) - cylinder.radius,
                      std::abs(local.y) - 0.5f * cylinder.height);
    return glm::length(glm::max(q, glm::vec2(0.0f))) + std::min(std::max(q.x, q.y), 0.0f);
}

float signed_distance(const GroundCollider& ground, glm::vec3 p) { return p.y - ground.height; }

void collide_all(State& state, const ColliderSettings& colliders, std::size_t begin, std::size_t end) {
    using T = double;
    end = std::min(end, state.size());
    const T thickness = colliders.thickness;
    if (colliders.sphere.enabled) collide_shape(state, colliders.sphere, T(colliders.sphere.friction), thickness, begin, end);
    if (colliders.cube.enabled) collide_shape(state, colliders.cube, T(colliders.cube.friction), thickness, begin, end);
    if (colliders.cylinder.enabled) collide_shape(state, colliders.cylinder, T(colliders.cylinder.friction), thickness, begin, end);
    if (colliders.ground.enabled) collide_shape(state, colliders.ground, T(colliders.ground.friction), thickness, begin, end);
}
// Whether the sphere, the cube or the cylinder (those enabled) may touch a particle in `box`.
bool shapes_may_touch(const ColliderSettings& colliders, const Box& box) {
    const float t = colliders.thickness;
    return (colliders.sphere.enabled && may_touch(colliders.sphere, t, box)) ||
           (colliders.cube.enabled && may_touch(colliders.cube, t, box)) ||
           (colliders.cylinder.enabled && may_touch(colliders.cylinder, t, box));
}

bool any_shape(const ColliderSettings& colliders) {
    return colliders.sphere.enabled || colliders.cube.enabled || colliders.cylinder.enabled;
}

BlockBounds block_bounds_for(const ColliderSettings& colliders, const CollisionBlocks& blocks) {
    if (!any_shape(colliders)) return BlockBounds::Lowest;
    return blocks.carried_valid && !shapes_may_touch(colliders, blocks.carried()) ? BlockBounds::Lowest
                                                                                   : BlockBounds::Box;
}

bool collide_stage(State& state, const ColliderSettings& colliders, bool broad_phase, CollisionBlocks& blocks,
                   StepProfile* profile, int threads, const MotionBounds* motion) {
    if (blocks.start.empty() || blocks.start.back() != state.size()) {
        blocks.start = block_starts(state.size(), 0, 0);
        blocks.current = blocks.boxes_current = false;
    }
    const std::size_t count = blocks.count();
    const bool shapes = any_shape(colliders);
    if (!shapes) blocks.carried_valid = false;  // grown only while a shape may need it
    if (!shapes && !colliders.ground.enabled) return false;
    const auto finite = [](glm::dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    const bool known = motion && !motion->empty && finite(motion->lo) && finite(motion->hi);
    if (!broad_phase) {
        blocks.boxes.resize(count);  // only counted: every block is tested
        blocks.current = blocks.boxes_current = blocks.carried_valid = false;
    } else if (!(blocks.current && blocks.boxes.size() == count)) {
        StageTimer timer(profile, Stage::BroadPhase);
        bool from_sweep = blocks.boxes_current && blocks.boxes.size() == count;
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
            if (!blocks.carried_valid || shapes_may_touch(colliders, blocks.carried())) {
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
            for (std::size_t k = 0; k < count; ++k) {
                Box& box = blocks.boxes[k];
                if (!from_sweep) box = particle_bounds(state.position, blocks.start[k], blocks.start[k + 1]);
                box.lo -= reach;
                box.hi += reach;
            }
        }
        blocks.cloth = union_of(blocks.boxes.data(), count);
        blocks.boxes_current = blocks.current = true;
    }
    const float thickness = colliders.thickness;
    long long tested = 0;
    // With Lowest boxes the shapes meet only the carried box, which none of them can reach (checked above).
    const Box shape_cloth = blocks.bounds == BlockBounds::Lowest ? blocks.carried() : blocks.cloth;
    if (colliders.sphere.enabled) {
        StageTimer timer(profile, Stage::Sphere);
        tested += collide_blocks(state, colliders.sphere, thickness, broad_phase, blocks, shape_cloth,
                                 collider_index(Stage::Sphere), threads, profile);
    }
    if (colliders.cube.enabled) {
        StageTimer timer(profile, Stage::Cube);
        tested += collide_blocks(state, colliders.cube, thickness, broad_phase, blocks, shape_cloth,
                                 collider_index(Stage::Cube), threads, profile);
    }
    if (colliders.cylinder.enabled) {
        StageTimer timer(profile, Stage::Cylinder);
        tested += collide_blocks(state, colliders.cylinder, thickness, broad_phase, blocks, shape_cloth,
                                 collider_index(Stage::Cylinder), threads, profile);
    }
    if (colliders.ground.enabled) {
        StageTimer timer(profile, Stage::Ground);
        tested += collide_blocks(state, colliders.ground, thickness, broad_phase, blocks, blocks.cloth,
                                 collider_index(Stage::Ground), threads, profile);
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

void collide(State& state, const SphereCollider& sphere, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, sphere, double(sphere.friction), double(thickness), begin, std::min(end, state.size()));
}
void collide(State& state, const CubeCollider& cube, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, cube, double(cube.friction), double(thickness), begin, std::min(end, state.size()));
}
void collide(State& state, const CylinderCollider& cylinder, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, cylinder, double(cylinder.friction), double(thickness), begin, std::min(end, state.size()));
}
void collide(State& state, const GroundCollider& ground, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, ground, double(ground.friction), double(thickness), begin, std::min(end, state.size()));
}


}  // namespace clothsim
