// Tethers (tethers.hpp): long-range attachments from each free particle to the pins it hangs from.
#include "every_kernel.hpp"
#include "support.hpp"

#include "simulation/mass_spring_internals.hpp"
#include "collision/broad_phase.hpp"
#include "collision/colliders.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/strain.hpp"
#include "model/tethers.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>

using namespace clothsim;

namespace {

// The largest distance of a tethered particle from its anchor, as a fraction of its rest distance, minus 1.
double worst_tether_strain(const MassSpring& sim, const Tethers& tethers) {
    double worst = -1.0;
    for (std::size_t t = 0; t < tethers.size(); ++t) {
        const double d = glm::length(sim.state().position.get(tethers.particle[t]) -
                                     sim.state().position.get(tethers.anchor[t]));
        worst = std::max(worst, d / tethers.rest[t] - 1.0);
    }
    return worst;
}

// The largest strain of a spring with one end pinned.
double strain_at_pins(const MassSpring& sim) {
    double worst = 0.0;
    for (const Spring& s : sim.topology().springs) {
        if ((sim.state().pinned[s.a] == kPinned) == (sim.state().pinned[s.b] == kPinned)) continue;
        const double d = glm::length(sim.state().position.get(s.b) - sim.state().position.get(s.a));
        worst = std::max(worst, d / s.rest_length - 1.0);
    }
    return worst;
}

Scene hanging(int n, float tether_strain) {
    Scene s = load_scene("hanging");  // cotton, stretch 1200 N/m, held by two point pins
    apply_override(s, "cloth.rows=" + std::to_string(n));
    apply_override(s, "cloth.cols=" + std::to_string(n));
    s.settings.springs.tether_strain = tether_strain;
    s.settings.solver.threads = 1;
    return s;
}

// `s` on the fast path with its tethers on `threads` threads, after `steps` steps.
MassSpring fast_run(Scene s, int threads, int steps) {
    s.settings.solver.threads = threads;
    s.settings.solver.method = SolverMethod::Fast;
    MassSpring fast = build_simulation(s);
    REQUIRE(fast.plan().path == StepPath::FastVerlet);
    REQUIRE(fast.plan().tethers);
    fast.run_steps(steps);
    return fast;
}

}  // namespace

TEST_CASE("tethers: each free particle is tied to the nearest pin of each pin cluster", "[tethers]") {
    Scene s = hanging(16, 0.01f);
    const std::size_t n = 16 * 16;
    CHECK(build_simulation(s).tether_count() == 2 * (n - 2));  // two corners: two clusters
    s.pins.preset = PinPreset::FourCorners;
    CHECK(build_simulation(s).tether_count() == 4 * (n - 4));
    s.pins.preset = PinPreset::TopRow;
    const MassSpring row = build_simulation(s);
    REQUIRE(row.tether_count() == n - 16);  // one pinned row: one cluster
    // Its nearest pinned particle is the one straight above it (row 0, the same column), at the rest distance.
    const Tethers tethers = build_tethers(row.topology(), row.state(), row.state().position);
    for (std::size_t t = 0; t < tethers.size(); ++t) {
        INFO("tether " << t);
        REQUIRE(tethers.anchor[t] == tethers.particle[t] % 16);
        CHECK(tethers.rest[t] == Approx(double(tethers.particle[t] / 16) / 15.0).epsilon(1e-6));
    }
    // Clips of 0.15 m at the two corners: each clip's particles are one cluster.
    s.pins.preset = PinPreset::TopCorners;
    s.pins.preset_radius = 0.15f;
    const MassSpring clips = build_simulation(s);
    std::size_t pinned = 0;
    for (std::uint8_t p : clips.state().pinned) pinned += p == kPinned;
    CHECK(pinned > 2);
    CHECK(clips.tether_count() == 2 * (n - pinned));
    // No pins, nothing to tie to: the stage is skipped and says why.
    s.pins = PinSpec{PinPreset::None, {}, 0.0f};
    const MassSpring loose = build_simulation(s);
    CHECK(loose.tether_count() == 0);
    CHECK_FALSE(loose.plan().tethers);
    bool said = false;
    for (const StageStatus& st : describe(loose.plan(), loose.topology(), loose.settings())) {
        if (st.stage == Stage::Tethers) said = st.note == "no pins to tie to";
    }
    CHECK(said);
}

TEST_CASE("tethers: a cloth hanging from two point pins never stretches past tether_strain from them, and the "
          "springs at the pins stretch no more than that", "[tethers]") {
    MassSpring free = build_simulation(hanging(32, 0.0f));
    MassSpring tied = build_simulation(hanging(32, 0.01f));
    REQUIRE(tied.plan().tethers);
    const Tethers tethers = build_tethers(tied.topology(), tied.state(), tied.state().position);
    REQUIRE(tethers.size() == tied.tether_count());
    double worst = -1.0;
    for (int step = 0; step < 120; ++step) {  // 2 s: the cloth swings down and hangs
        free.run_steps(1);
        tied.run_steps(1);
        worst = std::max(worst, worst_tether_strain(tied, tethers));
    }
    const double untied_pins = strain_at_pins(free), tied_pins = strain_at_pins(tied);
    INFO("strain at the pins: " << untied_pins << " without tethers, " << tied_pins << " with; worst tether "
                                << worst << "; max membrane strain " << max_membrane_strain(tied.topology(), tied.state().position)
                                << " with, " << max_membrane_strain(free.topology(), free.state().position) << " without");
    CHECK(worst <= 0.01 + 1e-12);  // after every step
    CHECK(worst > 0.005);          // and they do act: the cloth leans on them
    CHECK(tied_pins <= 0.01 + 1e-6);  // rest lengths are float: 1.01 L in double differs by ~1e-8
    CHECK(untied_pins > 0.02);  // the point pins' singular load, which the tethers take
    CHECK(tied.all_finite());
}

TEST_CASE("tethers: on the fast solver's bands and threads the cloth is the textbook solver's bit for bit, its "
          "hem lying on the ground, every kernel and thread count", "[tethers][fast_solver]") {
    // The fast path projects each band's tethers and boxes its collision blocks again on the thread that
    // swept the block (MassSpring::apply_tethers, box_blocks_on_team); the textbook path in one pass. A box
    // that missed a particle the tethers moved would leave it in the ground.
    test::with_every_kernel([] {
        Scene s = hanging(40, 0.001f);  // a tenth of the particles at their tethers' limit
        test::plane(s.settings.colliders).height = 1.0f;  // the hem (0.6 m when hanging straight) lies on it
        s.settings.solver.method = SolverMethod::Textbook;
        MassSpring textbook = build_simulation(s);
        REQUIRE(textbook.plan().path == StepPath::TextbookVerlet);
        textbook.run_steps(60);
        for (int threads : test::thread_counts({1, 2, 3})) {
            const MassSpring fast = fast_run(s, threads, 60);
            INFO(FastSolver::kernel_name() << ", " << threads << " thread(s)");
            CHECK(fast.tethers_at_limit() == textbook.tethers_at_limit());
            CHECK(fast.tethers_at_limit() > 0);
            CHECK(test::bit_identical(fast, textbook));
        }
        double lowest = INFINITY;
        for (std::size_t i = 0; i < textbook.particle_count(); ++i) {
            lowest = std::min(lowest, textbook.state().position.y[i]);
        }
        CHECK(lowest < 1.0 + 0.01);  // the hem does reach the ground
    });
}

TEST_CASE("tethers: on the fast path the cloth swings into a sphere as on the textbook path, bit for bit, the "
          "blocks boxed in the tethers' job, every kernel and thread count", "[tethers][fast_solver][broad_phase]") {
    // With no limit stage between them, each band boxes its blocks right after projecting its tethers
    // (MassSpring::apply_tethers); a tether at its limit widens the carried box, and when that turns the
    // lowest-point boxes into whole ones the blocks are boxed again. A box that missed a particle, or lowest
    // points kept while the sphere is within reach, would let the cloth through the sphere, which the
    // textbook path (every block boxed by the collision stage, in one pass) does not.
    test::with_every_kernel([] {
        Scene s = hanging(40, 0.001f);
        // In the path of the cloth swinging down from its pinned edge (z = -0.5, y = 1.6).
        test::collider(s.settings.colliders, "sphere") = Collider{SphereCollider{{0.0f, 1.1f, -0.2f}, 0.15f}, 0.3f, true, {}};
        s.settings.solver.method = SolverMethod::Textbook;
        MassSpring textbook = build_simulation(s);
        textbook.run_steps(60);
        Scene open = s;
        test::collider(open.settings.colliders, "sphere").enabled = false;
        MassSpring missed = build_simulation(open);
        missed.run_steps(60);
        REQUIRE_FALSE(test::bit_identical(missed, textbook));  // the sphere is met
        for (int threads : test::thread_counts({1, 2, 3})) {
            const MassSpring fast = fast_run(s, threads, 60);
            INFO(FastSolver::kernel_name() << ", " << threads << " thread(s)");
            CHECK(test::bit_identical(fast, textbook));
        }
    });
}

TEST_CASE("tethers: on the fast path the collision blocks' boxes after a substep bound the particles the tethers "
          "moved, every kernel and thread count", "[tethers][fast_solver][broad_phase]") {
    // The ground far below: the broad phase runs and no contact grows a box, so each box is exactly its
    // block's bounds after the tethers (the sweep's boxes, made before them, are not). Tethers at 0.1% keep
    // a tenth of the cloth's particles at their limit, block extremes among them. The boxes hold each block's
    // lowest point only (BlockBounds::Lowest: the ground alone, or a sphere out of reach of the carried box), or
    // whole boxes swept by the cloth's largest motion (the first substeps with the sphere).
    test::with_every_kernel([] {
        for (bool sphere : {false, true}) {
            for (int threads : test::thread_counts({1, 2, 3})) {
                Scene s = hanging(40, 0.001f);
                test::plane(s.settings.colliders).height = -10.0f;
                test::collider(s.settings.colliders, "sphere") = Collider{SphereCollider{{0.0f, 20.0f, 0.0f}, 1.0f}, 0.3f, sphere, {}};
                s.settings.solver.threads = threads;
                MassSpring fast = build_simulation(s);
                REQUIRE(fast.plan().path == StepPath::FastVerlet);
                fast.run_steps(45);  // released flat, it reaches the tethers' limit as it swings down
                int mismatched = 0, limited_substeps = 0;
                for (int substep = 0; substep < 300; ++substep) {
                    fast.substep();
                    limited_substeps += fast.tethers_at_limit() > 0;
                    const CollisionBlocks& blocks = collision_blocks(fast);
                    REQUIRE(blocks.boxes_current);
                    // With the sphere the stage sweeps each box by the cloth's largest motion (colliders.cpp).
                    const Box motion = particle_bounds(fast.state().motion, 0, fast.state().size());
                    const glm::vec3 reach = glm::max(glm::abs(motion.lo), glm::abs(motion.hi));
                    for (std::size_t k = 0; k < blocks.count(); ++k) {
                        Box want = particle_bounds(fast.state().position, blocks.start[k], blocks.start[k + 1]);
                        if (blocks.bounds == BlockBounds::Box) want = Box{want.lo - reach, want.hi + reach};
                        if (blocks.bounds == BlockBounds::Lowest) {
                            want = Box{glm::vec3(-INFINITY, want.lo.y, -INFINITY), glm::vec3(INFINITY)};
                        }
                        mismatched += !(blocks.boxes[k].lo == want.lo && blocks.boxes[k].hi == want.hi);
                    }
                }
                INFO(FastSolver::kernel_name() << ", " << threads << " thread(s), sphere " << sphere);
                CHECK(limited_substeps > 100);  // the tethers do move particles
                CHECK(mismatched == 0);
            }
        }
    });
}

TEST_CASE("tethers: slack tethers change nothing", "[tethers]") {
    // Cotton stretches by well under 50% anywhere: tethers that allow 50% are never reached, and the run is
    // bit-identical to one without them (the stage moves nothing it does not have to).
    MassSpring free = build_simulation(hanging(16, 0.0f));
    MassSpring slack = build_simulation(hanging(16, 0.5f));
    REQUIRE(slack.plan().tethers);
    free.run_steps(60);
    slack.run_steps(60);
    CHECK(slack.tethers_at_limit() == 0);
    CHECK(test::bit_identical(free, slack));
}

TEST_CASE("tethers: freeing a pin unties its particles, pinning one ties them to it", "[tethers]") {
    MassSpring sim = build_simulation(hanging(16, 0.01f));
    const std::size_t n = 16 * 16;
    sim.set_pinned(0, false);
    CHECK(sim.tether_count() == n - 1);
    sim.run_steps(60);  // the freed corner falls away from where its pin was: nothing holds it there
    CHECK(glm::length(sim.state().position.get(0) - glm::dvec3(-0.5, 1.6, -0.5)) > 0.3);
    sim.set_pinned(sim.topology().index(15, 8), true);
    CHECK(sim.tether_count() == 2 * (n - 2));
    sim.set_pinned(15, false);
    sim.set_pinned(sim.topology().index(15, 8), false);
    CHECK(sim.tether_count() == 0);
    CHECK_FALSE(sim.plan().tethers);
}

TEST_CASE("tethers: a tethered pendulum released level swings down with the speed energy allows, never more",
          "[tethers]") {
    // Two particles 1 m apart, no spring between them: the pinned one holds the other by a tether alone
    // (L = 1 m, strain 1%, so a rigid pendulum of 1.01 m once taut). Released level, the free particle
    // falls straight down until the tether catches it at a drop d with 1 + d^2 = 1.01^2; the catch removes
    // the radial part of its speed sqrt(2 g d); from there it swings as a pendulum. At the bottom:
    //   v^2 = v_t^2 + 2 g (1.01 - d),  v_t = sqrt(2 g d) (1 / 1.01)  (the tangential part at the catch).
    for (const Integrator integrator : {Integrator::Verlet, Integrator::SymplecticEuler}) {
        Scene s;
        s.cloth.rows = 1;
        s.cloth.cols = 2;
        s.cloth.size = {1.0f, 1.0f};
        s.cloth.mass = 2.0f;
        s.cloth.origin = {0.0f, 0.0f, 0.0f};
        s.pins = PinSpec{PinPreset::None, {Pin{0, 0, 0.0f}}, 0.0f};
        s.settings.springs = {glm::vec2(0.0f), 0.0f, glm::vec2(0.0f), 0.0f};
        s.settings.springs.tether_strain = 0.01f;
        test::collider(s.settings.colliders, "ground").enabled = false;
        s.settings.integration.integrator = integrator;
        s.settings.integration.substeps = 200;
        MassSpring sim = build_simulation(s);
        REQUIRE(sim.tether_count() == 1);
        const double g = 9.81, L = 1.01, d = std::sqrt(L * L - 1.0);
        const double vt = std::sqrt(2.0 * g * d) / L;
        const double v_bottom = std::sqrt(vt * vt + 2.0 * g * (L - d));
        const double v_energy = std::sqrt(2.0 * g * L);  // no loss at all: the bound
        double lowest = 0.0, speed_at_lowest = 0.0, worst = 0.0;
        for (int sub = 0; sub < 200 * 40; ++sub) {  // 0.67 s: past the bottom (a quarter swing is 0.5 s)
            sim.substep();
            const glm::dvec3 x = sim.state().position.get(1);
            worst = std::max(worst, glm::length(x) - L);
            if (x.y < lowest) {
                lowest = x.y;
                speed_at_lowest = glm::length(sim.velocities()[1]);
            }
        }
        INFO(integrator_names()[static_cast<int>(integrator)] << ": lowest " << lowest << " m at " << speed_at_lowest << " m/s; analytic "
                                         << v_bottom << " m/s (bound " << v_energy << ")");
        CHECK(worst <= 1e-12);
        CHECK(lowest == Approx(-L).epsilon(1e-4));
        CHECK(speed_at_lowest == Approx(v_bottom).epsilon(0.01));
        CHECK(speed_at_lowest <= v_energy);
    }
}

TEST_CASE("tethers: a mesh cloth's tethers and integration on the team give the list path's cloth bit for bit, every "
          "kernel and thread count", "[tethers][cloth_mesh]") {
    // `skirt` (2005 vertices held at the waist, on the mannequin) with tethers at 0.1%: on the fast method its
    // springs and hinges (the element gather), its integration and its tethers run in pieces on the team; on the
    // textbook method in one pass each.
    Scene s = load_scene("skirt");
    s.settings.springs.tether_strain = 0.001f;
    s.settings.solver.method = SolverMethod::Textbook;
    MassSpring textbook = build_simulation(s);
    REQUIRE(textbook.topology().mesh);
    REQUIRE(textbook.plan().tethers);
    REQUIRE(textbook.mesh_team_threads() == 0);
    textbook.run_steps(10);
    test::with_every_kernel([&] {
        for (int threads : test::thread_counts({1, 2, 3})) {
            s.settings.solver.threads = threads;
            s.settings.solver.method = SolverMethod::Fast;
            MassSpring fast = build_simulation(s);
            REQUIRE(fast.mesh_team_threads() == threads);
            fast.run_steps(10);
            INFO(FastSolver::kernel_name() << ", " << threads << " thread(s)");
            CHECK(fast.tethers_at_limit() == textbook.tethers_at_limit());
            CHECK(fast.tethers_at_limit() > 0);
            CHECK(test::bit_identical(fast, textbook));
        }
    });
}
