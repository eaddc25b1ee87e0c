// The collision broad phase: boxes around particle blocks, and may_touch, which must be conservative (a
// particle a collider would move always lies in a box the test accepts), or culling would change results.
#include "every_kernel.hpp"
#include "support.hpp"

#include "simulation/mass_spring_internals.hpp"
#include "clothsim/mesh_shapes.hpp"
#include "collision/broad_phase.hpp"
#include "collision/colliders.hpp"
#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

using namespace clothsim;

namespace {

// The box of the finite coordinates of particles [begin, end), the plain way.
Box reference_bounds(const DVec3Array& p, std::size_t begin, std::size_t end) {
    Box b;
    for (std::size_t i = begin; i < end; ++i) {
        const glm::vec3 q = p.get(i);
        for (int a = 0; a < 3; ++a) {
            if (std::isnan(q[a])) continue;
            b.lo[a] = std::min(b.lo[a], q[a]);
            b.hi[a] = std::max(b.hi[a], q[a]);
        }
    }
    return b;
}

// The substep's motion of the probed particles: for friction to act on, and a path for the swept test.
const glm::vec3 kMotion(0.001f, -0.002f, 0.0005f);

// A box grown to hold where the substep started too (x - motion), as the collision stage's swept boxes do.
Box swept(Box box) {
    return {glm::min(box.lo, box.lo - kMotion), glm::max(box.hi, box.hi - kMotion)};
}

// Whether the collider moves a lone free particle at p (or changes its motion).
bool collider_moves(const Collider& collider, float thickness, glm::vec3 p) {
    State st = test::free_particles({p}, 1.0f);
    st.motion.set(0, kMotion);
    const State before = st;
    collide(st, collider, thickness, 0, 1);
    return !(st.position == before.position) || !(st.motion == before.motion);
}

// A signed offset spread over many magnitudes, to probe both sides of the surface at every scale.
float offset(std::mt19937& rng) {
    std::uniform_real_distribution<float> exponent(-9.0f, -0.5f);  // below float spacing too
    std::bernoulli_distribution sign(0.5);
    return (sign(rng) ? 1.0f : -1.0f) * std::pow(10.0f, exponent(rng));
}

float pick_scale(std::mt19937& rng) {
    constexpr float kScales[] = {0.0f, 1.0f, 30.0f, 1000.0f};
    return kScales[std::uniform_int_distribution<int>(0, 3)(rng)];
}

glm::vec3 random_vec(std::mt19937& rng, float half_width) {
    std::uniform_real_distribution<float> u(-half_width, half_width);
    return {u(rng), u(rng), u(rng)};
}

glm::vec3 random_direction(std::mt19937& rng) {
    std::normal_distribution<float> n(0.0f, 1.0f);
    glm::vec3 d;
    do d = {n(rng), n(rng), n(rng)};
    while (glm::length(d) < 1e-3f);
    return glm::normalize(d);
}

// Tallies of a conservativeness run, so that a test that never probes the boundary fails.
struct Tally {
    long long rejected = 0, accepted = 0, moved = 0, near_rejected = 0;
};

// Checks one particle: if its one-point box is rejected, the collider must not move it; then the same for
// a small box around it (every corner and the centre).
void check_conservative(const Collider& collider, float thickness, glm::vec3 p, std::mt19937& rng, Tally& tally) {
    const bool moves = collider_moves(collider, thickness, p);
    tally.moved += moves;
    if (may_touch(collider, thickness, swept(Box{p, p}))) {
        ++tally.accepted;
    } else {
        ++tally.rejected;
        // Near: within 1 mm of the reach, past the swept box's growth.
        tally.near_rejected += std::abs(signed_distance(collider, p) - thickness) < 1e-3f + glm::length(kMotion);
        if (moves) {
            FAIL_CHECK("rejected particle (" << p.x << ", " << p.y << ", " << p.z << ") is moved; thickness "
                                             << thickness << ", signed distance " << signed_distance(collider, p));
        }
    }
    std::uniform_real_distribution<float> extent(0.0f, 0.05f);
    const glm::vec3 e(extent(rng), extent(rng), extent(rng));
    const Box box{p - e, p + e};
    if (may_touch(collider, thickness, swept(box))) return;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 q((corner & 1) ? box.hi.x : box.lo.x, (corner & 2) ? box.hi.y : box.lo.y,
                          (corner & 4) ? box.hi.z : box.lo.z);
        if (collider_moves(collider, thickness, q)) {
            FAIL_CHECK("corner (" << q.x << ", " << q.y << ", " << q.z << ") of a rejected box is moved");
        }
    }
}

constexpr int kTrials = 20000;

// The random cases must have exercised all three outcomes, or the conservativeness check proved little.
void check_coverage(const Tally& tally) {
    INFO("rejected " << tally.rejected << " (" << tally.near_rejected << " near the surface), accepted "
                     << tally.accepted << ", moved " << tally.moved);
    CHECK(tally.rejected > kTrials / 8);
    CHECK(tally.near_rejected > kTrials / 40);
    CHECK(tally.moved > kTrials / 4);
}

}  // namespace

TEST_CASE("broad_phase particle_bounds is the box of the finite coordinates of its range", "[broad_phase]") {
    std::mt19937 rng(11);
    DVec3Array p;
    p.resize(21);  // past two AVX2 blocks of 8, with a tail
    for (std::size_t i = 0; i < p.size(); ++i) p.set(i, random_vec(rng, 5.0f));
    for (std::size_t i : {0u, 3u, 9u, 17u, 20u}) p.set(i, glm::vec3(NAN));  // in vector blocks and in the tail
    p.x[5] = NAN;  // one coordinate NaN: that coordinate is left out
    p.z[12] = NAN;
    for (std::size_t begin = 0; begin <= p.size(); ++begin) {
        for (std::size_t end = begin; end <= p.size(); ++end) {
            INFO("range [" << begin << ", " << end << ")");
            const Box got = particle_bounds(p, begin, end);
            const Box want = reference_bounds(p, begin, end);
            CHECK(got.empty() == want.empty());
            if (want.empty()) continue;
            CHECK(got.lo == want.lo);
            CHECK(got.hi == want.hi);
            CHECK(std::isfinite(got.lo.x + got.lo.y + got.lo.z + got.hi.x + got.hi.y + got.hi.z));
        }
    }
    // An empty range, and a range of NaN particles only, give the empty box, which touches nothing.
    CHECK(particle_bounds(p, 4, 4).empty());
    CHECK(particle_bounds(p, 7, 2).empty());
    CHECK(particle_bounds(p, 0, 1).empty());
    CHECK(Box{}.empty());
    const Box none = particle_bounds(p, 3, 4);
    REQUIRE(none.empty());
    CHECK_FALSE(may_touch(SphereCollider{glm::vec3(0.0f), 1e6f}, 1.0f, none));
    CHECK_FALSE(may_touch(BoxCollider{glm::vec3(0.0f), glm::vec3(1e6f)}, 1.0f, none));
    CHECK_FALSE(may_touch(CylinderCollider{glm::vec3(0.0f), 1e6f, 1e6f}, 1.0f, none));
    CHECK_FALSE(may_touch(PlaneCollider{1e6f}, 1.0f, none));
}

TEST_CASE("broad_phase union_of is the box around its boxes, a NaN bound left out, as folding glm::min and glm::max",
          "[broad_phase]") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> coord(-5.0f, 5.0f);
    std::uniform_int_distribution<int> pick(0, 19);
    for (std::size_t n : {0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u, 17u, 256u}) {
        std::vector<Box> boxes(n);
        for (Box& b : boxes) {
            const int kind = pick(rng);
            if (kind == 0) continue;  // empty
            b.lo = glm::vec3(coord(rng), coord(rng), coord(rng));
            b.hi = b.lo + glm::vec3(1.0f);
            if (kind == 1) b.lo.y = NAN;
            if (kind == 2) b.hi.z = NAN;
        }
        Box plain;
        for (const Box& b : boxes) plain.lo = glm::min(plain.lo, b.lo), plain.hi = glm::max(plain.hi, b.hi);
        const Box fast = union_of(boxes.data(), n);
        INFO(n << " boxes");
        for (int c = 0; c < 3; ++c) {
            CHECK(fast.lo[c] == plain.lo[c]);  // never NaN: NaN bounds are left out by both
            CHECK(fast.hi[c] == plain.hi[c]);
        }
        if (n == 0) CHECK(fast.empty());
    }
}

TEST_CASE("broad_phase block_starts cuts grid rows into runs of kBlockParticles and row_block_bounds boxes them",
          "[broad_phase]") {
    // A grid: every row on its own, cut into runs of at most kBlockParticles, in row order. A row holds two
    // groups of eight full blocks (the AVX-512 kernel's unit), two more full blocks and a partial one.
    const int rows = 3, cols = static_cast<int>(18 * kBlockParticles + 5);
    const std::size_t per_row = blocks_per_row(cols);
    const std::size_t n = static_cast<std::size_t>(rows) * cols;
    const std::vector<std::size_t> starts = block_starts(n, rows, cols);
    REQUIRE(per_row == 19);
    REQUIRE(starts.size() == static_cast<std::size_t>(rows) * per_row + 1);
    for (int r = 0; r < rows; ++r) {
        for (std::size_t j = 0; j < per_row; ++j) {
            CHECK(starts[r * per_row + j] == static_cast<std::size_t>(r) * cols + j * kBlockParticles);
        }
    }
    CHECK(starts.back() == n);
    CHECK(blocks_per_row(static_cast<int>(kBlockParticles)) == 1);
    // Not a grid (rows x cols is not the particle count): runs of the particle list.
    const std::vector<std::size_t> list = block_starts(40, 0, 0);
    CHECK(list == std::vector<std::size_t>{0, kBlockParticles, 2 * kBlockParticles, 40});
    CHECK(block_starts(0, 0, 0) == std::vector<std::size_t>{0});

    // The boxes of one row's blocks are those particle_bounds gives, with every kernel: NaN particles in the
    // first and last lane of a block, in the second group of eight, in the single blocks and in the partial
    // one; a whole block of NaN particles in each group of eight (the empty box); infinite coordinates.
    std::mt19937 rng(4);
    DVec3Array p;
    p.resize(n);
    for (std::size_t i = 0; i < n; ++i) p.set(i, random_vec(rng, 3.0f));
    const std::size_t row = static_cast<std::size_t>(cols);
    for (std::size_t i : {std::size_t{1}, std::size_t{15}, std::size_t{16 * 9 + 7}, std::size_t{16 * 16 + 3},
                          row + 16 * 17 + 15, n - 1, n - 4}) {
        p.set(i, glm::vec3(NAN));
    }
    p.x[2 * row + 40] = NAN;  // one coordinate only
    p.y[2 * row + 41] = INFINITY;
    p.z[2 * row + 16 * 12] = -INFINITY;
    for (std::size_t i = row; i < row + kBlockParticles; ++i) p.set(i, glm::vec3(NAN));
    for (std::size_t i = 2 * row + 16 * 13; i < 2 * row + 16 * 14; ++i) p.set(i, glm::vec3(NAN));
    test::with_every_kernel([&] {
        std::vector<Box> boxes(per_row);
        for (int r = 0; r < rows; ++r) {
            const std::size_t begin = static_cast<std::size_t>(r) * cols;
            row_block_bounds(p, begin, static_cast<std::size_t>(cols), boxes.data());
            for (std::size_t j = 0; j < boxes.size(); ++j) {
                INFO(FastSolver::kernel_name(FastSolver::kernel()) << ": row " << r << ", block " << j);
                const std::size_t b = starts[r * per_row + j], e = starts[r * per_row + j + 1];
                const Box want = reference_bounds(p, b, e);
                CHECK(boxes[j].empty() == want.empty());
                if (want.empty()) continue;
                CHECK(boxes[j].lo == want.lo);
                CHECK(boxes[j].hi == want.hi);
            }
            // Only the lowest points: the same lo.y, the other sides open; empty where the block has no y.
            std::vector<Box> lowest(per_row);
            row_block_bounds(p, begin, static_cast<std::size_t>(cols), lowest.data(), BlockBounds::Lowest);
            for (std::size_t j = 0; j < lowest.size(); ++j) {
                INFO(FastSolver::kernel_name(FastSolver::kernel()) << ": lowest, row " << r << ", block " << j);
                const Box want = reference_bounds(p, starts[r * per_row + j], starts[r * per_row + j + 1]);
                CHECK(lowest[j].empty() == !(want.lo.y < INFINITY));
                if (lowest[j].empty()) continue;
                CHECK(lowest[j].lo == glm::vec3(-INFINITY, want.lo.y, -INFINITY));
                CHECK(lowest[j].hi == glm::vec3(INFINITY));
            }
        }
    });
    CHECK(particle_bounds(p, row, row + kBlockParticles).empty());
}

TEST_CASE("broad_phase block_bounds_for asks for lowest points when no collider but the ground can reach the cloth",
          "[broad_phase]") {
    ColliderSettings c;
    test::collider(c, "ground").enabled = true;
    CollisionBlocks blocks;
    CHECK(block_bounds_for(c, blocks) == BlockBounds::Lowest);  // the ground alone
    test::collider(c, "sphere") = Collider{SphereCollider{{0.0f, 5.0f, 0.0f}, 0.5f}, 0.3f, true, {}};
    CHECK(block_bounds_for(c, blocks) == BlockBounds::Box);  // no valid carried box
    blocks.carried_valid = true;
    blocks.carried_lo = glm::dvec3(-1.0, 0.0, -1.0), blocks.carried_hi = glm::dvec3(1.0, 2.0, 1.0);
    CHECK(block_bounds_for(c, blocks) == BlockBounds::Lowest);  // the sphere is 2.5 m above it
    blocks.carried_hi.y = 4.6;
    CHECK(block_bounds_for(c, blocks) == BlockBounds::Box);  // within its radius
    blocks.carried_hi.y = 2.0;
    test::collider(c, "cube") = Collider{BoxCollider{{0.0f, 1.0f, 1.2f}, {0.5f, 0.5f, 0.5f}}, 0.3f, true, {}};
    CHECK(block_bounds_for(c, blocks) == BlockBounds::Box);
    test::collider(c, "cube").enabled = false;
    test::collider(c, "cylinder") = Collider{CylinderCollider{{3.0f, 1.0f, 0.0f}, 0.5f, 1.0f}, 0.3f, true, {}};
    CHECK(block_bounds_for(c, blocks) == BlockBounds::Lowest);
    test::cylinder(c).center.x = 1.4f;
    CHECK(block_bounds_for(c, blocks) == BlockBounds::Box);
    // The ground reads nothing of a box but its lowest y: an open box tests as the whole one.
    const PlaneCollider ground{0.2f};
    for (float y : {-1.0f, 0.19f, 0.2f, 0.2049f, 0.21f, 3.0f}) {
        const Box whole{{0.3f, y, -0.4f}, {0.5f, y + 0.7f, 0.1f}};
        const Box open{{-INFINITY, y, -INFINITY}, glm::vec3(INFINITY)};
        CHECK(may_touch(ground, 0.005f, open) == may_touch(ground, 0.005f, whole));
    }
}

TEST_CASE("broad_phase a cloth hanging onto the ground moves the same with or without a far sphere",
          "[broad_phase][fast_solver]") {
    // `hanging` with the ground raised into its reach: the hem lands and the ground pushes particles. With the
    // ground alone the fast solver's boxes hold the lowest points only. A sphere far out of reach adds whole
    // boxes on the first substep and whenever a push on the ground drops the carried box, and changes nothing
    // else, so both runs must be bit-identical, every kernel and thread count.
    test::with_every_kernel([] {
        for (int threads : test::thread_counts({1, 2})) {
            Scene s = load_scene("hanging");
            apply_override(s, "cloth.rows=24");
            apply_override(s, "cloth.cols=24");
            test::plane(s.settings.colliders).height = 1.0f;
            s.settings.solver.threads = threads;
            Scene with_sphere = s;
            test::collider(with_sphere.settings.colliders, "sphere") =
                Collider{SphereCollider{{0.0f, 30.0f, 0.0f}, 1.0f}, 0.3f, true, {}};
            REQUIRE(block_bounds_for(s.settings.colliders, CollisionBlocks{}) == BlockBounds::Lowest);
            MassSpring lowest = build_simulation(s), whole = build_simulation(with_sphere);
            REQUIRE(lowest.plan().path == StepPath::FastVerlet);
            lowest.set_profiling(true);
            lowest.run_steps(60);
            whole.run_steps(60);
            INFO(FastSolver::kernel_name() << ", " << threads << " thread(s)");
            CHECK(test::bit_identical(lowest, whole));
            double low = INFINITY;
            for (double y : lowest.state().position.y) low = std::min(low, y);
            CHECK(low < 1.0 + 2.0 * s.settings.colliders.thickness);  // on the ground
            const StepProfile& profile = lowest.profile();
            const std::size_t ground = Collider::of(PlaneCollider{}).kind();
            CHECK(profile.blocks_tested[ground] > 0);
            CHECK(profile.blocks_tested[ground] < profile.blocks_offered[ground]);  // the rest are culled
        }
    });
}

namespace {

// `hanging` at 40 x 40 with tethers (at 0.1% a tenth of the particles are at their limit, and the hem stays
// above 0.598 m) and a sphere below the hanging cloth (its top at 0.57 m) that the carried box reaches again
// and again as it grows.
Scene hanging_over_sphere(int threads, bool broad_phase, float tether_strain = 0.001f) {
    Scene s = load_scene("hanging");
    apply_override(s, "cloth.rows=40");
    apply_override(s, "cloth.cols=40");
    s.settings.springs.tether_strain = tether_strain;
    test::collider(s.settings.colliders, "sphere") = Collider{SphereCollider{{0.0f, 0.37f, -0.3f}, 0.2f}, 0.3f, true, {}};
    s.settings.solver.threads = threads;
    s.settings.solver.broad_phase = broad_phase;
    return s;
}

bool inside(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& p) {
    // The carried box starts from whole boxes rounded to the nearest float: within the tests' margin.
    const auto margin = [](double v) { return 1e-6 * (1.0 + std::abs(v)); };
    for (int a = 0; a < 3; ++a) {
        if (!(p[a] >= lo[a] - margin(lo[a]) && p[a] <= hi[a] + margin(hi[a]))) return false;
    }
    return true;
}

}  // namespace

TEST_CASE("broad_phase the carried box holds every particle, and the blocks hold what the colliders read, every "
          "kernel and thread count", "[broad_phase][fast_solver]") {
    // Without tethers nothing runs after the first collision stage, so the boxes seen after a substep are the
    // ones that stage used: whole ones appear when the carried box reached the sphere.
    test::with_every_kernel([] {
        for (const int threads : test::thread_counts({1, 2, 3})) {
          for (const float tethers : {0.001f, 0.0f}) {
            if (tethers == 0.0f && threads == 3) continue;  // without tethers: one and two threads
            MassSpring fast = build_simulation(hanging_over_sphere(threads, true, tethers));
            MassSpring every = build_simulation(hanging_over_sphere(threads, false, tethers));
            REQUIRE(fast.plan().path == StepPath::FastVerlet);
            int lowest = 0, whole = 0, outside = 0, mismatched = 0;
            for (int substep = 0; substep < 4000; ++substep) {
                fast.substep();
                every.substep();
                const State& st = fast.state();
                const CollisionBlocks& blocks = collision_blocks(fast);
                REQUIRE(blocks.boxes_current);
                if (blocks.carried_valid) {  // every particle and the start of its path (x - motion)
                    for (std::size_t i = 0; i < st.size(); ++i) {
                        const glm::dvec3 x = st.position.get(i);
                        outside += !inside(blocks.carried_lo, blocks.carried_hi, x);
                        outside += !inside(blocks.carried_lo, blocks.carried_hi, x - st.motion.get(i));
                    }
                }
                // Whole boxes are the blocks' bounds swept by the cloth's largest motion; lowest points are open boxes.
                const Box motion = particle_bounds(st.motion, 0, st.size());
                const glm::vec3 reach = glm::max(glm::abs(motion.lo), glm::abs(motion.hi));
                const bool box = blocks.bounds == BlockBounds::Box;
                (box ? whole : lowest) += 1;
                for (std::size_t k = 0; k < blocks.count(); ++k) {
                    const Box tight = particle_bounds(st.position, blocks.start[k], blocks.start[k + 1]);
                    const Box want = box ? Box{tight.lo - reach, tight.hi + reach}
                                         : Box{glm::vec3(-INFINITY, tight.lo.y, -INFINITY), glm::vec3(INFINITY)};
                    mismatched += !(blocks.boxes[k].lo == want.lo && blocks.boxes[k].hi == want.hi);
                }
            }
            INFO(FastSolver::kernel_name() << ", " << threads << " thread(s), tethers " << tethers << ": " << lowest
                                           << " substeps with lowest points, " << whole << " with whole boxes");
            CHECK(outside == 0);
            CHECK(mismatched == 0);
            CHECK(lowest > 3000);                  // mostly the cheap boxes ...
            if (tethers == 0.0f) CHECK(whole >= 2);  // ... whole ones first, and again once it reached the sphere
            CHECK(test::bit_identical(fast, every));  // culling changes nothing
          }
        }
    });
}

TEST_CASE("broad_phase a cloth moved into the sphere between steps is pushed out of it", "[broad_phase]") {
    // Edits move particles outside the substeps, where the carried box does not follow them: it must be
    // dropped. The whole cloth is moved as one piece (no spring pulls a particle back out) into the sphere.
    std::vector<MassSpring> runs;
    for (bool broad_phase : {true, false}) {
        INFO("broad phase " << broad_phase);
        MassSpring sim = build_simulation(hanging_over_sphere(1, broad_phase, 0.0f));
        sim.run_steps(3);  // the carried box is still far above the sphere
        if (broad_phase) {
            REQUIRE(collision_blocks(sim).bounds == BlockBounds::Lowest);
            REQUIRE(collision_blocks(sim).carried_lo.y > 1.0);
        }
        const SphereCollider& sphere = test::sphere(sim.settings().colliders);
        const glm::dvec3 centre(sphere.center);
        const glm::dvec3 shift = centre - sim.state().position.get(40 * 20 + 20);  // a middle particle to the centre
        const std::vector<glm::vec3> velocity = sim.velocities();
        for (std::size_t i = 0; i < sim.state().size(); ++i) {
            sim.set_particle(i, glm::vec3(sim.state().position.get(i) + shift), velocity[i]);
        }
        sim.substep();
        int inside_sphere = 0;
        for (std::size_t i = 0; i < sim.state().size(); ++i) {
            if (sim.state().pinned[i]) continue;
            inside_sphere += glm::length(sim.state().position.get(i) - centre) <
                             sphere.radius + sim.settings().colliders.thickness - 1e-5;
        }
        CHECK(inside_sphere == 0);
        runs.push_back(std::move(sim));
    }
    CHECK(test::bit_identical(runs[0], runs[1]));
}

TEST_CASE("broad_phase a sphere turned off, then on again where the cloth has moved, is not culled", "[broad_phase]") {
    // While no sphere, cube or cylinder is enabled the carried box is not grown: it must not survive to the
    // next one. The cloth swings down with the sphere off; the sphere comes back around its middle.
    std::vector<MassSpring> runs;
    for (bool broad_phase : {true, false}) {
        INFO("broad phase " << broad_phase);
        MassSpring sim = build_simulation(hanging_over_sphere(1, broad_phase, 0.0f));
        sim.run_steps(3);
        if (broad_phase) REQUIRE(collision_blocks(sim).bounds == BlockBounds::Lowest);
        test::edit_settings(sim, [](SimulationSettings& s) { test::collider(s.colliders, "sphere").enabled = false; });
        sim.run_steps(25);
        const glm::vec3 middle(sim.state().position.get(40 * 20 + 20));
        test::edit_settings(sim, [&](SimulationSettings& s) {
            test::collider(s.colliders, "sphere") =
                Collider{SphereCollider{middle + glm::vec3(0.0f, 0.0f, 0.02f), 0.1f}, 0.3f, true, {}};
        });
        sim.substep();
        const SphereCollider& sphere = test::sphere(sim.settings().colliders);
        int inside_sphere = 0;
        for (std::size_t i = 0; i < sim.state().size(); ++i) {
            inside_sphere += glm::length(sim.state().position.get(i) - glm::dvec3(sphere.center)) <
                             sphere.radius + sim.settings().colliders.thickness - 1e-5;
        }
        CHECK(inside_sphere == 0);
        runs.push_back(std::move(sim));
    }
    CHECK(test::bit_identical(runs[0], runs[1]));
}

TEST_CASE("broad_phase collide_stage takes the reach from the caller's bounds of the motion, from a pass when they "
          "are not finite", "[broad_phase]") {
    ColliderSettings colliders;
    test::collider(colliders, "sphere") = Collider{SphereCollider{{0.0f, 5.0f, 0.0f}, 0.3f}, 0.4f, true, {}};  // out of reach
    std::mt19937 rng(8);
    State st = test::free_state(100);
    for (std::size_t i = 0; i < 100; ++i) {
        st.position.set(i, random_vec(rng, 1.0f));
        st.motion.set(i, 0.01f * random_vec(rng, 1.0f));
    }
    const auto boxes_with = [&](const MotionBounds* motion) {
        CollisionBlocks blocks;
        State copy = st;
        collide_stage(copy, colliders, true, blocks, nullptr, 1, motion);
        return blocks.boxes;
    };
    const auto same = [](const std::vector<Box>& a, const std::vector<Box>& b) {
        bool equal = a.size() == b.size();
        for (std::size_t k = 0; equal && k < a.size(); ++k) equal = a[k].lo == b[k].lo && a[k].hi == b[k].hi;
        return equal;
    };
    const std::vector<Box> pass = boxes_with(nullptr);
    MotionBounds exact;
    include_motion(st.motion, 0, st.size(), exact);
    CHECK(same(boxes_with(&exact), pass));
    MotionBounds nan = exact;
    nan.lo.y = NAN;  // a NaN motion in the sweep's lanes
    CHECK(same(boxes_with(&nan), pass));
    MotionBounds larger = exact;  // the bounds are used when finite: a larger reach grows every box further
    larger.hi.x += 1.0;
    const std::vector<Box> grown = boxes_with(&larger);
    REQUIRE(grown.size() == pass.size());
    CHECK(grown[0].hi.x > pass[0].hi.x);
}

TEST_CASE("broad_phase may_touch rejects a far box and accepts a box holding the collider's centre",
          "[broad_phase]") {
    const SphereCollider sphere{{0.0f, 0.5f, 0.0f}, 0.3f};
    const BoxCollider cube{{1.0f, 0.4f, -2.0f}, {0.5f, 0.2f, 0.8f}};
    const CylinderCollider cylinder{{-1.0f, 0.3f, 1.0f}, 0.09f, 0.6f};
    const PlaneCollider ground{-0.25f};
    const float t = 0.005f;
    const Box far{{10.0f, 10.0f, 10.0f}, {11.0f, 12.0f, 13.0f}};
    CHECK_FALSE(may_touch(sphere, t, far));
    CHECK_FALSE(may_touch(cube, t, far));
    CHECK_FALSE(may_touch(cylinder, t, far));
    CHECK_FALSE(may_touch(ground, t, far));
    CHECK(may_touch(sphere, t, Box{sphere.center - 0.01f, sphere.center + 0.01f}));
    CHECK(may_touch(sphere, t, Box{sphere.center, sphere.center}));
    CHECK(may_touch(cube, t, Box{cube.center - 0.01f, cube.center + 0.01f}));
    CHECK(may_touch(cube, t, Box{{-100.0f, -100.0f, -100.0f}, {100.0f, 100.0f, 100.0f}}));  // encloses it
    CHECK(may_touch(ground, t, Box{{0.0f, -0.3f, 0.0f}, {1.0f, 2.0f, 1.0f}}));
    // Just outside the reach (surface + thickness) by far more than the rounding margin: rejected.
    const glm::vec3 above = sphere.center + glm::vec3(0.0f, sphere.radius + t + 0.01f, 0.0f);
    CHECK_FALSE(may_touch(sphere, t, Box{above, above + 0.1f}));
    CHECK_FALSE(may_touch(ground, t, Box{{0.0f, ground.height + t + 0.01f, 0.0f}, {1.0f, 5.0f, 1.0f}}));
    const float right = cube.center.x + 0.5f * cube.size.x + t + 0.01f;
    CHECK_FALSE(may_touch(cube, t, Box{{right, 0.0f, -2.0f}, {right + 1.0f, 1.0f, -1.0f}}));
    // The cylinder: a box holding its centre, one on its axis above it, above the top face's reach and beside
    // the side's reach; a box in the corner of its bounding box, beyond the round side, is rejected too.
    CHECK(may_touch(cylinder, t, Box{cylinder.center, cylinder.center}));
    const float top = cylinder.center.y + 0.5f * cylinder.height;
    CHECK(may_touch(cylinder, t, Box{{-1.0f, top + t - 0.001f, 1.0f}, {-1.0f, top + 1.0f, 1.0f}}));
    CHECK_FALSE(may_touch(cylinder, t, Box{{-1.0f, top + t + 0.01f, 1.0f}, {-1.0f, top + 1.0f, 1.0f}}));
    const float beside = cylinder.center.x + cylinder.radius + t + 0.01f;
    CHECK_FALSE(may_touch(cylinder, t, Box{{beside, 0.0f, 0.5f}, {beside + 1.0f, 0.5f, 1.5f}}));
    const float corner = cylinder.radius * 0.8f;  // (0.8, 0.8) R from the axis: 1.13 R, beyond R + t
    const glm::vec3 c(cylinder.center.x + corner, cylinder.center.y, cylinder.center.z + corner);
    CHECK_FALSE(may_touch(cylinder, t, Box{c, c + 0.1f}));
}

TEST_CASE("broad_phase may_touch never rejects a particle the sphere would move", "[broad_phase]") {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> radius(0.01f, 2.0f), thickness(0.0f, 0.02f);
    Tally tally;
    for (int trial = 0; trial < kTrials; ++trial) {
        const SphereCollider sphere{random_vec(rng, pick_scale(rng)), radius(rng)};
        const float t = trial % 10 == 0 ? 0.0f : thickness(rng);
        const glm::vec3 p = sphere.center + random_direction(rng) * (sphere.radius + t + offset(rng));
        check_conservative(Collider{sphere, 0.4f, true, {}}, t, p, rng, tally);
    }
    check_coverage(tally);
}

TEST_CASE("broad_phase may_touch never rejects a particle the cube would move", "[broad_phase]") {
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> edge(0.01f, 2.0f), thickness(0.0f, 0.02f), unit(-1.0f, 1.0f);
    std::uniform_int_distribution<int> axis(0, 2);
    Tally tally;
    for (int trial = 0; trial < kTrials; ++trial) {
        const BoxCollider cube{random_vec(rng, pick_scale(rng)), {edge(rng), edge(rng), edge(rng)}};
        const float t = trial % 10 == 0 ? 0.0f : thickness(rng);
        const glm::vec3 reach = 0.5f * cube.size + t;
        // A point near a face, or (one time in three) near an edge or a corner too.
        glm::vec3 local(unit(rng) * reach.x, unit(rng) * reach.y, unit(rng) * reach.z);
        const int snapped = trial % 3 == 0 ? 1 + axis(rng) : 1;
        for (int s = 0; s < snapped; ++s) {
            const int a = axis(rng);
            local[a] = (unit(rng) < 0.0f ? -1.0f : 1.0f) * (reach[a] + offset(rng));
        }
        check_conservative(Collider{cube, 0.4f, true, {}}, t, cube.center + local, rng, tally);
    }
    check_coverage(tally);
}

TEST_CASE("broad_phase may_touch never rejects a particle the cylinder would move", "[broad_phase]") {
    std::mt19937 rng(6);
    std::uniform_real_distribution<float> size(0.01f, 2.0f), thickness(0.0f, 0.02f), unit(-1.0f, 1.0f);
    std::uniform_real_distribution<float> angle(0.0f, 6.2831853f);
    Tally tally;
    for (int trial = 0; trial < kTrials; ++trial) {
        const CylinderCollider cylinder{random_vec(rng, pick_scale(rng)), size(rng), size(rng)};
        const float t = trial % 10 == 0 ? 0.0f : thickness(rng);
        const float reach_r = cylinder.radius + t, reach_y = 0.5f * cylinder.height + t;
        // A point near the side, near a face, or (one time in three) near a rim: at the reach plus an offset.
        const float a = angle(rng);
        float r = std::abs(unit(rng)) * reach_r, y = unit(rng) * reach_y;
        const int kind = trial % 3;
        if (kind != 1) r = reach_r + offset(rng);
        if (kind != 0) y = (unit(rng) < 0.0f ? -1.0f : 1.0f) * (reach_y + offset(rng));
        if (kind == 2 && r > cylinder.radius && std::abs(y) > 0.5f * cylinder.height) {
            // Beyond the rim the shell is round: probe around the rim's circle at radius t + offset.
            const float b = std::uniform_real_distribution<float>(0.0f, 1.5707963f)(rng);
            const float d = std::max(t + offset(rng), 0.0f);
            r = cylinder.radius + d * std::cos(b);
            y = (y < 0.0f ? -1.0f : 1.0f) * (0.5f * cylinder.height + d * std::sin(b));
        }
        const glm::vec3 p = cylinder.center + glm::vec3(r * std::cos(a), y, r * std::sin(a));
        check_conservative(Collider{cylinder, 0.4f, true, {}}, t, p, rng, tally);
    }
    check_coverage(tally);
}

TEST_CASE("broad_phase may_touch never rejects a particle a mesh would move", "[broad_phase]") {
    // An icosphere mesh (1280 triangles), turned, scaled and moved at random; particles near its surface.
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> radius(0.05f, 2.0f), thickness(0.0f, 0.02f), angle(-180.0f, 180.0f);
    const auto ball = std::make_shared<const TriangleMesh>(icosphere(1.0, 3));
    Tally tally;
    std::uniform_int_distribution<std::size_t> triangle(0, ball->triangles().size() - 1);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    // The trials come in runs of kRun that share a scale and a thickness (so a run shares its contact grid, which
    // the mesh builds once per band); position, rotation and the point change every trial.
    constexpr int kRun = 100;
    float scale = 1.0f, t = 0.0f;
    for (int trial = 0; trial < kTrials; ++trial) {
        if (trial % kRun == 0) {
            scale = radius(rng);
            t = trial % (10 * kRun) == 0 ? 0.0f : thickness(rng);
        }
        MeshCollider mesh;
        mesh.mesh = ball;
        mesh.scale = scale;
        mesh.position = random_vec(rng, pick_scale(rng));
        mesh.rotation = {angle(rng), angle(rng), angle(rng)};
        // A point on a random triangle, moved along its normal by the thickness and a small offset.
        const std::size_t k = triangle(rng);
        const auto& v = ball->vertices();
        const auto& tri = ball->triangles()[k];
        double a = unit(rng), b = unit(rng);
        if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
        const PlacedMesh at = placed(mesh);
        const glm::dvec3 on = at.to_world(v[tri[0]] + a * (v[tri[1]] - v[tri[0]]) + b * (v[tri[2]] - v[tri[0]]));
        const glm::vec3 p = glm::vec3(on + at.rotation * ball->face_normals()[k] * double(t + offset(rng)));
        check_conservative(Collider{mesh, 0.4f, true, {}}, t, p, rng, tally);
    }
    // The mesh's test is as loose as its leaf boxes (a few triangles each): it rejects far boxes, not near ones.
    INFO("rejected " << tally.rejected << ", accepted " << tally.accepted << ", moved " << tally.moved);
    CHECK(tally.rejected > kTrials / 20);
    CHECK(tally.moved > kTrials / 4);
}

TEST_CASE("broad_phase may_touch never rejects a particle the ground would move", "[broad_phase]") {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> thickness(0.0f, 0.02f);
    Tally tally;
    for (int trial = 0; trial < kTrials; ++trial) {
        const float scale = pick_scale(rng);
        const PlaneCollider ground{std::uniform_real_distribution<float>(-1.0f, 1.0f)(rng) * scale};
        const float t = trial % 10 == 0 ? 0.0f : thickness(rng);
        glm::vec3 p = random_vec(rng, scale + 1.0f);
        p.y = ground.height + t + offset(rng);
        check_conservative(Collider{ground, 0.5f, true, {}}, t, p, rng, tally);
    }
    check_coverage(tally);
}

namespace {
// A mesh collider: an icosphere of radius 0.15 m (1280 triangles) at (0.2, 0.5, -0.25), turned 20 degrees about y.
MeshCollider ball_mesh() {
    MeshCollider m;
    m.mesh = std::make_shared<const TriangleMesh>(icosphere(0.15, 3));
    m.position = {0.2f, 0.5f, -0.25f};
    m.rotation = {0.0f, 20.0f, 0.0f};
    return m;
}
}  // namespace

TEST_CASE("broad_phase collide_stage with culling moves every particle exactly as testing them all", "[broad_phase]") {
    ColliderSettings colliders;
    colliders.shapes = {
        Collider{SphereCollider{{0.0f, 0.3f, 0.0f}, 0.3f}, 0.4f, true, {}},  // resting on the ground
        Collider{BoxCollider{{0.5f, 0.2f, 0.1f}, {0.4f, 0.4f, 0.3f}}, 0.3f, true, {}},
        Collider{CylinderCollider{{-0.3f, 0.25f, -0.3f}, 0.09f, 0.5f}, 0.3f, true, {}},  // on the ground too
        Collider{PlaneCollider{0.0f}, 0.5f, true, {}},
        Collider{ball_mesh(), 0.3f, true, {}},
    };
    colliders.thickness = 0.005f;

    // A particle inside the sphere near its bottom is pushed below the ground: its block's box must be
    // brought up to date so that the ground, tested next, still sees it.
    {
        State st = test::free_particles({{0.0f, 0.05f, 0.0f}, {2.0f, 1.0f, 2.0f}}, 1.0f);
        CollisionBlocks blocks;
        blocks.start = {0, 1, 2};  // one particle per block
        StepProfile profile;
        collide_stage(st, colliders, true, blocks, &profile);
        INFO("particle at (" << st.position.x[0] << ", " << st.position.y[0] << ", " << st.position.z[0] << ")");
        CHECK(st.position.y[0] >= test::plane(colliders).height + colliders.thickness);
        const std::size_t ground = Collider::of(PlaneCollider{}).kind();
        CHECK(profile.blocks_tested[ground] == 1);  // the far particle's block is culled
        CHECK(profile.blocks_offered[ground] == 2);
    }

    std::mt19937 rng(5);
    std::uniform_real_distribution<float> x(-0.5f, 1.0f), y(-0.05f, 0.8f), z(-0.5f, 0.5f), m(-0.01f, 0.01f);
    for (std::size_t size : {std::size_t{1}, std::size_t{7}, kBlockParticles, std::size_t{64}}) {
        INFO("blocks of " << size);
        State culled = test::free_state(600);
        for (std::size_t i = 0; i < 600; ++i) {
            culled.position.set(i, {x(rng), y(rng), z(rng)});
            culled.motion.set(i, {m(rng), m(rng), m(rng)});
            if (i % 97 == 0) culled.pinned[i] = 1;
        }
        // Sort by x so that blocks are compact and many lie out of reach of one collider or another.
        std::vector<std::size_t> order(600);
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::sort(order.begin(), order.end(),
                  [&](std::size_t a, std::size_t b) { return culled.position.x[a] < culled.position.x[b]; });
        State sorted = culled;
        for (std::size_t i = 0; i < order.size(); ++i) {
            sorted.position.set(i, culled.position.get(order[i]));
            sorted.motion.set(i, culled.motion.get(order[i]));
            sorted.pinned[i] = culled.pinned[order[i]];
        }
        State all = sorted;
        CollisionBlocks blocks;
        for (std::size_t b = 0; b < 600; b += size) blocks.start.push_back(b);
        blocks.start.push_back(600);
        StepProfile profile;
        collide_stage(sorted, colliders, true, blocks, &profile);
        collide_all(all, colliders);
        CHECK(sorted.position == all.position);
        CHECK(sorted.motion == all.motion);
        CHECK(!(sorted.position == culled.position));  // something was pushed
        for (std::size_t c = 0; c < kColliderKindCount; ++c) {
            INFO("collider " << c << ": " << profile.blocks_tested[c] << " of " << profile.blocks_offered[c]);
            CHECK(profile.blocks_tested[c] > 0);
            if (size <= kBlockParticles) CHECK(profile.blocks_tested[c] < profile.blocks_offered[c]);
        }
    }
}

TEST_CASE("broad_phase collide_stage shared by threads moves every particle exactly as testing them all", "[broad_phase]") {
    ColliderSettings colliders;
    colliders.shapes = {
        Collider{SphereCollider{{0.0f, 0.3f, 0.0f}, 0.3f}, 0.4f, true, {}},
        Collider{BoxCollider{{0.5f, 0.2f, 0.1f}, {0.4f, 0.4f, 0.3f}}, 0.3f, true, {}},
        Collider{CylinderCollider{{-0.3f, 0.25f, -0.3f}, 0.09f, 0.5f}, 0.3f, true, {}},
        Collider{PlaneCollider{0.0f}, 0.5f, true, {}},
        Collider{ball_mesh(), 0.3f, true, {}},
    };
    colliders.thickness = 0.005f;
    // Enough particles for the stage to share its blocks among threads, in the cloth's order (blocks along x).
    const std::size_t n = 4 * kParallelCollisionParticles + 333;  // the ground's threshold too
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> x(-0.5f, 1.0f), y(-0.05f, 0.8f), z(-0.5f, 0.5f), m(-0.01f, 0.01f);
    State start = test::free_state(n);
    std::vector<float> xs(n);
    for (float& v : xs) v = x(rng);
    std::sort(xs.begin(), xs.end());
    for (std::size_t i = 0; i < n; ++i) {
        start.position.set(i, {xs[i], y(rng), z(rng)});
        start.motion.set(i, {m(rng), m(rng), m(rng)});
        if (i % 97 == 0) start.pinned[i] = 1;
    }
    State all = start;
    collide_all(all, colliders);
    for (int threads : {1, 2, 3}) {
        INFO(threads << " threads");
        State shared = start;
        CollisionBlocks blocks;
        blocks.start = block_starts(n, 0, 0);
        StepProfile profile;
        collide_stage(shared, colliders, true, blocks, &profile, threads);
        CHECK(shared.position == all.position);
        CHECK(shared.motion == all.motion);
        for (std::size_t c = 0; c < kColliderKindCount; ++c) CHECK(profile.blocks_tested[c] < profile.blocks_offered[c]);
    }
    CHECK(!(all.position == start.position));  // something was pushed
}
