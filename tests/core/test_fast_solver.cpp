// The fast solver against the textbook solver (the oracle), determinism across thread counts, and
// the fallbacks (generic kernel, non-grid topologies).
#include "every_kernel.hpp"
#include "integrators/fast_solver.hpp"
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "collision/colliders.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstring>
#include <optional>
#include <utility>

using namespace clothsim;

namespace {

// Largest particle distance between two runs, over the cloth's size (its larger side).
double max_relative_difference(const MassSpring& a, const MassSpring& b, const Scene& scene) {
    double worst = 0.0;
    for (std::size_t i = 0; i < a.particle_count(); ++i) {
        worst = std::max(worst, static_cast<double>(glm::length(a.position(i) - b.position(i))));
    }
    return worst / std::max(scene.cloth.size.x, scene.cloth.size.y);
}

MassSpring run(Scene scene, SolverMethod method, int threads, long long substeps) {
    scene.settings.solver.method = method;
    scene.settings.solver.threads = threads;
    MassSpring sim = build_simulation(scene);
    REQUIRE(sim.fast_solver_available());
    for (long long i = 0; i < substeps; ++i) sim.substep();
    return sim;
}

// `scene` resized to cols x cols, after 20 steps (a cloth whose particles move differently), and a fast solver
// for its grid.
std::pair<MassSpring, FastSolver> moving(Scene scene, int cols) {
    scene.cloth.rows = scene.cloth.cols = cols;
    MassSpring sim = build_simulation(scene);
    sim.run_steps(20);
    std::optional<FastSolver> solver = FastSolver::for_topology(sim.topology());
    REQUIRE(solver);
    return {std::move(sim), std::move(*solver)};
}

}  // namespace

TEST_CASE("fast solver agrees with the textbook solver to 1e-5 of the cloth size after 1000 steps", "[fast_solver]") {
    for (const std::string& name : bundled_scene_names()) {
        const Scene scene = test::scene_for_loops(name);  // the stiff scenes on a coarser grid (support.hpp)
        // The fast solver runs Verlet; XPBD's grid form has its own oracle (test_grid_xpbd.cpp: stiff-drape). A mesh
        // cloth (skirt, cape) has no grid for it.
        if (scene.settings.integration.integrator != Integrator::Verlet || scene.cloth.is_mesh()) continue;
        const MassSpring textbook = run(scene, SolverMethod::Textbook, 1, 1000);
        const MassSpring fast = run(scene, SolverMethod::Fast, 2, 1000);
        const double difference = max_relative_difference(textbook, fast, scene);
        INFO(name << ": max |x_fast - x_textbook| / size = " << difference << " (kernel " << FastSolver::kernel_name()
                  << ")");
        CHECK(difference < 1e-5);
        // Stronger, and by design: both solvers do the same operations in the same order (see
        // fast_solver.cpp), so they agree bit for bit; rounding differences would otherwise grow
        // exponentially in wrinkling cloth (measured: 1e-9 after 2 substeps, 2e-3 after 1000).
        CHECK(difference == 0.0);
        CHECK(fast.all_finite());
    }
}

TEST_CASE("fast solver: every kernel this CPU runs agrees with the textbook solver bit for bit", "[fast_solver]") {
    test::with_every_kernel([] {
        // Per spring: the skip-one springs' sweeps (the material's bends with every kernel: the next test).
        for (const char* name : {"hanging", "drape-sphere", "flag"}) {
            const Scene scene = per_spring_scene(name);
            const MassSpring textbook = run(scene, SolverMethod::Textbook, 1, 1000);
            const MassSpring fast = run(scene, SolverMethod::Fast, 2, 1000);
            INFO(name << " with the " << FastSolver::kernel_name() << " kernel");
            CHECK(test::bit_identical(fast, textbook));
        }
    });
}

TEST_CASE("fast solver: a material cloth (bends, half-weight edges, warp and weft) agrees with the textbook solver "
          "bit for bit with every kernel and thread count", "[fast_solver][material]") {
    Scene scene = load_scene("hanging");  // its cotton gives way to the fabric set field by field below
    scene.cloth.rows = 40;                // blocks of 8 rows and more for up to 5 threads
    scene.cloth.cols = 37;        // not a multiple of 8: every kernel's tail runs
    scene.material.enabled = true;
    scene.material.density = 0.2f;
    scene.material.stretch = {3000.0f, 1500.0f};
    scene.material.shear = 60.0f;
    scene.material.bending = {2e-5f, 5e-6f};
    scene.settings.forces.wind = {1.0f, 0.0f, 3.0f};  // wind and a guard-free substep count
    scene.settings.integration.substeps = 80;
    const MassSpring textbook = run(scene, SolverMethod::Textbook, 1, 300);
    REQUIRE(textbook.bend_count() > 0);
    REQUIRE(textbook.all_finite());
    test::with_every_kernel([&] {
        for (int threads : {1, 2, 5}) {
            const MassSpring fast = run(scene, SolverMethod::Fast, threads, 300);
            INFO("kernel " << FastSolver::kernel_name() << ", " << threads << " threads");
            CHECK(test::bit_identical(fast, textbook));
        }
    });
}

TEST_CASE("fast solver: a material with stretch curves agrees with the textbook solver bit for bit with every kernel "
          "and thread count, and its knots are passed", "[fast_solver][stretch_curve]") {
    Scene scene = load_scene("hanging");
    scene.cloth.rows = 24;
    scene.cloth.cols = 21;  // not a multiple of 8: every kernel's tail runs
    scene.material.stretch = {1500.0f, 800.0f};
    scene.material.stretch_curve.u = {{0.0005f, 3.0f}, {0.002f, 8.0f}};
    scene.material.stretch_curve.v = {{0.001f, 2.5f}};
    scene.material.explicit_fields |= kMaterialStretch | kMaterialStretchCurve;
    derive_springs(scene);
    REQUIRE(scene.settings.springs.stretch_curve[0].knots == 2);
    scene.settings.integration.substeps = 60;
    const MassSpring textbook = run(scene, SolverMethod::Textbook, 1, 300);
    REQUIRE(textbook.all_finite());
    // Some springs along each axis are past their last knot: the curve's terms run.
    double largest[2] = {0.0, 0.0};
    for (const Spring& sp : textbook.topology().springs) {
        if (sp.kind != SpringKind::Structural) continue;
        const double strain = glm::length(textbook.position(sp.b) - textbook.position(sp.a)) / sp.rest_length - 1.0;
        double& most = largest[sp.axis == Axis::V ? 1 : 0];
        most = std::max(most, strain);
    }
    CHECK(largest[0] > 0.002);
    CHECK(largest[1] > 0.001);
    test::with_every_kernel([&] {
        for (int threads : test::thread_counts({1, 2, 3})) {
            const MassSpring fast = run(scene, SolverMethod::Fast, threads, 300);
            INFO("kernel " << FastSolver::kernel_name() << ", " << threads << " threads");
            CHECK(test::bit_identical(fast, textbook));
        }
    });
}

TEST_CASE("fast solver gives bit-identical positions for any thread count", "[fast_solver]") {
    for (const char* name : {"flag", "drape-cube", "curtain"}) {
        Scene scene = per_spring_scene(name);  // the material's thread counts: the test above
        scene.cloth.rows = 64;  // enough rows for several blocks (8 rows at least each)
        scene.cloth.cols = 48;
        const MassSpring one = run(scene, SolverMethod::Fast, 1, 300);
        for (int threads : {2, 3, 4, 7}) {
            const MassSpring many = run(scene, SolverMethod::Fast, threads, 300);
            INFO(name << " with " << threads << " threads (" << many.solver_threads() << " blocks)");
            CHECK(many.solver_threads() == threads);
            CHECK(test::bit_identical(one, many));
        }
    }
}

TEST_CASE("fast solver agrees with the textbook solver bit for bit on a cloth draped over the cylinder",
          "[fast_solver]") {
    // drape-sphere with a cylinder where the sphere was, its top face where the sphere's top is: 1000
    // substeps take the cloth onto the top face, over the rim and down the side, through the broad phase
    // (the fast solver's block boxes) and the cylinder's projection with friction and continuous collision.
    // Per spring: at its 38 substeps a step 1000 substeps are 0.44 s, enough to fall that far.
    Scene scene = per_spring_scene("drape-sphere");
    test::collider(scene.settings.colliders, "sphere").enabled = false;
    test::collider(scene.settings.colliders, "cylinder") = Collider{CylinderCollider{{0.0f, 0.425f, 0.0f}, 0.3f, 0.85f}, 0.4f, true, {}};
    const MassSpring textbook = run(scene, SolverMethod::Textbook, 1, 1000);
    const CylinderCollider& c = test::cylinder(scene.settings.colliders);
    for (int threads : {1, 2, 3}) {
        INFO(threads << " threads");
        const MassSpring fast = run(scene, SolverMethod::Fast, threads, 1000);
        CHECK(fast.plan().path == StepPath::FastVerlet);
        CHECK(fast.profile().runs_of(Stage::Colliders) == 1000);
        CHECK(fast.profile().blocks_offered[2] > 0);  // the cylinder (kind 2) was tested
        CHECK(fast.all_finite());
        CHECK(test::bit_identical(fast, textbook));
    }
    // The cloth lies on the cylinder: some particles in its shell, none inside.
    float closest = INFINITY;
    for (std::size_t i = 0; i < textbook.particle_count(); ++i) {
        closest = std::min(closest, signed_distance(c, textbook.position(i)));
    }
    CHECK(closest >= 0.0f);
    CHECK(closest < 1.01f * scene.settings.colliders.thickness);
}

TEST_CASE("fast solver keeps pins fixed and every particle outside the colliders", "[fast_solver]") {
    Scene scene = per_spring_scene("drape-sphere");  // 38 substeps a step: 120 steps stay short
    scene.pins.particles = {{0, 0}, {39, 39}};
    MassSpring sim = run(scene, SolverMethod::Fast, 2, 0);
    const glm::vec3 a = sim.position(0), b = sim.position(39 * 40 + 39);
    sim.run_steps(120);
    CHECK(sim.position(0) == a);
    CHECK(sim.position(39 * 40 + 39) == b);
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        if (sim.particle(i).pinned) continue;
        CHECK(glm::length(sim.position(i) - test::sphere(scene.settings.colliders).center) >=
              test::sphere(scene.settings.colliders).radius);
        CHECK(sim.position(i).y >= test::plane(scene.settings.colliders).height);
    }
}

TEST_CASE("fast solver is only used for grid topologies, others run the textbook path", "[fast_solver]") {
    Topology t;
    t.rows = 1;
    t.cols = 3;
    t.springs = {{0, 2, 1.0f, SpringKind::Structural}};  // two apart but structural: not a grid spring
    CHECK_FALSE(FastSolver::for_topology(t).has_value());
    t.springs = {{0, 1, 1.0f, SpringKind::Structural}, {1, 0, 1.0f, SpringKind::Structural}};  // a duplicate
    CHECK_FALSE(FastSolver::for_topology(t).has_value());
    // A missing spring is a slot of weight 0 (a disc's outline): still a grid.
    t.springs = {{0, 1, 1.0f, SpringKind::Structural}};
    CHECK(FastSolver::for_topology(t).has_value());
    t.springs = {{0, 1, 1.0f, SpringKind::Structural, Axis::U, 0, 0.3f}};  // a weight that is no power of two
    CHECK_FALSE(FastSolver::for_topology(t).has_value());
    t.springs.clear();
    t.bends = {{0, 2, 1, Axis::U, 1.0f}};  // a bend whose middle is not between its ends
    CHECK_FALSE(FastSolver::for_topology(t).has_value());
    t.bends = {{0, 1, 2, Axis::U, 1.0f}};
    CHECK(FastSolver::for_topology(t).has_value());
    t.springs = {{0, 2, 2.0f, SpringKind::Bending}};  // skip-one springs and bends both
    CHECK_FALSE(FastSolver::for_topology(t).has_value());
    t.bends.clear();
    t.springs = {{1, 0, 1.0f, SpringKind::Structural}, {2, 1, 1.0f, SpringKind::Structural},
                 {0, 2, 2.0f, SpringKind::Bending}};  // either end may come first
    CHECK(FastSolver::for_topology(t).has_value());

    const State st = test::free_particles({{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {2.5f, 0.0f, 0.0f}}, 1.0f);
    Topology odd;
    odd.rows = 1;
    odd.cols = 3;
    odd.springs = {{0, 2, 2.0f, SpringKind::Structural}};
    SimulationSettings settings;
    test::collider(settings.colliders, "ground").enabled = false;
    settings.forces.gravity = glm::vec3(0.0f);
    MassSpring sim(odd, st, settings);
    CHECK_FALSE(sim.fast_solver_available());
    sim.run_steps(5);  // falls back to the textbook path: the stretched spring pulls its ends together
    CHECK(sim.position(0).x > 0.0f);
    CHECK(sim.position(1).x == 1.0f);
}

TEST_CASE("fast solver steps every band when OpenMP gives fewer threads than bands", "[fast_solver]") {
    // Inside an active parallel region (nested parallelism off by default) the solver's own region gets a
    // team of one thread: every band must still be stepped, and bit-identically.
    Scene scene = per_spring_scene("hanging");  // 64 x 32 at the scene's substeps: stable per spring
    scene.cloth.rows = 64;
    const MassSpring one = run(scene, SolverMethod::Fast, 1, 100);
    scene.settings.solver.method = SolverMethod::Fast;
    scene.settings.solver.threads = 4;
    MassSpring nested = build_simulation(scene);
#pragma omp parallel num_threads(2)
    {
#pragma omp single
        for (int i = 0; i < 100; ++i) nested.substep();
    }
    CHECK(nested.solver_threads() == 4);
    CHECK(test::bit_identical(one, nested));
}

TEST_CASE("fast solver: automatic threads switch between the team and one thread without changing a bit") {
    Scene s = load_scene("drape-sphere");
    s.settings.solver.threads = 0;
    MassSpring automatic = build_simulation(s);
    s.settings.solver.threads = 1;
    MassSpring one = build_simulation(s);
    for (int i = 0; i < 600; ++i) {  // several probes of the other choice (every 64 substeps at first)
        automatic.substep();
        one.substep();
    }
    CHECK(automatic.positions() == one.positions());
}

TEST_CASE("fast solver sees particles moved between its substeps by collisions, limits, pins, tools and another "
          "integrator", "[fast_solver]") {
    // Every move made outside the fast solver's sweep must be what its next substep reads: the same actions
    // on the textbook solver give the same bits. Each action comes where nothing else moves a particle.
    // Per spring: at 38 substeps a step the 1500 substeps below reach the sphere.
    Scene scene = per_spring_scene("drape-sphere");
    scene.cloth.rows = scene.cloth.cols = 24;
    scene.pins.particles = {{0, 0}};
    auto script = [&](SolverMethod method, int threads) {
        Scene s = scene;
        s.settings.solver.method = method;
        s.settings.solver.threads = threads;
        MassSpring sim = build_simulation(s);
        // Each action comes after substeps in the air, where nothing else moves a particle, so a stale copy
        // would show.
        auto set_method = [&](SolverMethod m) { test::edit_settings(sim, [&](SimulationSettings& t) { t.solver.method = m; }); };
        auto set_integrator = [&](Integrator i) {
            test::edit_settings(sim, [&](SimulationSettings& t) { t.integration.integrator = i; });
        };
        for (int i = 0; i < 5; ++i) sim.substep();
        sim.set_particle(100, sim.position(100) + glm::vec3(0.0f, 0.01f, 0.0f), {0.0f, 0.1f, 0.0f});
        sim.substep();
        sim.move_pinned(0, sim.position(0) + glm::vec3(0.01f, 0.0f, 0.0f));
        sim.substep();
        set_integrator(Integrator::Rk4);
        sim.substep();
        set_integrator(Integrator::Verlet);
        sim.substep();
        set_method(SolverMethod::Textbook);
        sim.substep();
        set_method(method);
        sim.substep();
        // Limits correct positions after the substep (the cloth falls faster than 1 cm/s by now).
        test::edit_settings(sim, [](SimulationSettings& t) {
            t.springs.strain_limit = 0.02f;
            t.forces.max_speed = 0.01f;
        });
        sim.substep();
        test::edit_settings(sim, [](SimulationSettings& t) {
            t.springs.strain_limit = 0.0f;
            t.forces.max_speed = 0.0f;
        });
        sim.substep();
        for (int i = 0; i < 1500; ++i) sim.substep();  // onto the sphere: collisions move particles
        CHECK(test::collider(sim.settings().colliders, "sphere").enabled);
        double nearest = INFINITY;  // to the sphere's centre
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            nearest = std::min(nearest, double(glm::length(sim.position(i) - test::sphere(sim.settings().colliders).center)));
        }
        CHECK(nearest < test::sphere(sim.settings().colliders).radius + 2.0 * sim.settings().colliders.thickness);
        return sim;
    };
    const MassSpring textbook = script(SolverMethod::Textbook, 1);
    for (int threads : {1, 2}) {
        INFO(threads << " threads");
        const MassSpring fast = script(SolverMethod::Fast, threads);
        CHECK(fast.all_finite());
        CHECK(test::bit_identical(fast, textbook));
    }
}

TEST_CASE("fast solver: the motion bounds its sweep takes leave NaN motions out, as a pass over the motions does",
          "[fast_solver]") {
    // The collision stage takes the swept boxes' reach and grows the carried box from these bounds: a NaN
    // motion must not hide a finite one. Column c uses lane c mod 8: a large motion at column 3 and a NaN one
    // at column 11 of the same row share a lane, and so do the tail's columns (40 = 2 x 16 + 8 with AVX-512).
    test::with_every_kernel([] {
        Scene scene = per_spring_scene("drape-sphere");
        auto [sim, solver] = moving(scene, 40);
        for (int threads : {1, 3}) {
            scene.settings.solver.threads = threads;
            State state = sim.state();
            for (std::size_t row : {5u, 30u}) {
                state.motion.y[row * 40 + 3] = -0.5;  // far beyond any other particle's motion
                state.motion.z[row * 40 + 35] = 0.5;
                state.position.x[row * 40 + 11] = NAN;  // NaN motions at columns 10-12 after the substep
                state.position.x[row * 40 + 39] = NAN;
            }
            MotionBounds b;
            solver.step(state, scene.settings, 7u, nullptr, sim.substep_length(), scene.settings.springs.damping, nullptr, &b);
            MotionBounds pass;
            include_motion(state.motion, 0, state.size(), pass);
            INFO(FastSolver::kernel_name() << ", " << threads << " thread(s)");
            REQUIRE(std::isnan(state.motion.x[5 * 40 + 11]));
            CHECK(b.lo == pass.lo);
            CHECK(b.hi == pass.hi);
            CHECK(b.lo.y < -0.4);
            CHECK(b.hi.z > 0.4);
        }
    });
}

TEST_CASE("fast solver: the motion bounds its sweep takes are those of every particle's new motion, for every kernel "
          "and thread count, and taking them changes no position", "[fast_solver]") {
    test::with_every_kernel([] {
        // drape-sphere in its per-spring form (a sagging, swinging cloth whose motions differ per particle, no
        // pins) and hanging in its material form (pinned corners, bends). 40 columns take the row update's
        // vector loop and its tail with AVX-512 (16 columns a vector), the vector loop alone with AVX2 and the
        // generic kernel (8); 21 columns both loops with all three; 13 the tail alone with AVX-512.
        for (const auto& [name, cols] : {std::pair{"drape-sphere", 40}, std::pair{"drape-sphere", 13},
                                         std::pair{"hanging", 21}, std::pair{"hanging", 40}}) {
            Scene scene = std::string(name) == "hanging" ? load_scene(name) : per_spring_scene(name);
            auto [sim, solver] = moving(scene, cols);
            for (int threads : {1, 3}) {
                scene.settings.solver.threads = threads;
                State state = sim.state();
                // A force on every particle besides the springs' (the row update's form with external forces).
                Vec3Array external;
                external.resize(state.size());
                for (std::size_t i = 0; i < state.size(); ++i) external.set(i, glm::vec3(0.01f * float(i % 7), 0.0f, -0.02f));
                for (int substep = 0; substep < 6; ++substep) {
                    const Vec3Array* ext = substep % 2 ? &external : nullptr;
                    State plain = state;  // the same substep without the bounds
                    solver.step(plain, scene.settings, 7u, ext, sim.substep_length(), scene.settings.springs.damping, nullptr, nullptr);
                    MotionBounds b;
                    solver.step(state, scene.settings, 7u, ext, sim.substep_length(), scene.settings.springs.damping, nullptr, &b);
                    INFO(name << " " << cols << " x " << cols << ", " << FastSolver::kernel_name() << ", " << threads
                              << " thread(s), substep " << substep);
                    CHECK(state.position == plain.position);
                    CHECK(state.motion == plain.motion);
                    REQUIRE_FALSE(b.empty);
                    const DVec3Array& m = state.motion;
                    glm::dvec3 lo = m.get(0), hi = m.get(0);
                    for (std::size_t i = 1; i < state.size(); ++i) lo = glm::min(lo, m.get(i)), hi = glm::max(hi, m.get(i));
                    CHECK(b.lo == lo);
                    CHECK(b.hi == hi);
                    CHECK(b.spread() > 0.0);  // a real spread, not a degenerate one
                }
            }
        }
    });
}

TEST_CASE("fast solver: the block boxes its sweep leaves are particle_bounds of every block after the update, NaN "
          "particles left out, for every kernel and thread count, and taking them changes no position",
          "[fast_solver][broad_phase]") {
    test::with_every_kernel([] {
        // 48 columns: three whole blocks of kBlockParticles (16); 40: two and a partial one; 13: a partial block
        // alone. Substeps alternate the row update with and without the motion's bounds (its two loops).
        for (int cols : {48, 40, 13}) {
            Scene scene = per_spring_scene("drape-sphere");
            auto [sim, solver] = moving(scene, cols);
            for (int threads : {1, 3}) {
                scene.settings.solver.threads = threads;
                State state = sim.state();
                // NaN particles in the first block of row 5, the last block of row 9 and the third row from the
                // bottom (every thread's rows): the springs spread NaN to their neighbours in all three
                // coordinates substep by substep, and a box leaves them out. The one in row 5 is held still
                // (inverse mass 0, no motion) with only x NaN: its y and z stay in its block's box.
                const std::size_t held = 5 * cols + 3;
                state.position.x[held] = NAN;
                state.inverse_mass[held] = 0.0f;
                state.motion.set(held, glm::dvec3(0.0));
                state.position.z[9 * cols + cols - 1] = NAN;
                state.position.y[(cols - 3) * cols + cols / 2] = NAN;
                const std::vector<std::size_t> start = block_starts(state.size(), cols, cols);
                for (int substep = 0; substep < 4; ++substep) {
                    const bool motion = substep % 2 == 1;  // the row update with and without the motion's bounds
                    State plain = state;
                    solver.step(plain, scene.settings, 7u, nullptr, sim.substep_length(), scene.settings.springs.damping, nullptr, nullptr);
                    // Boxes the sweep must overwrite, as the collision stage's vector is reused between substeps.
                    std::vector<Box> boxes(start.size() - 1, Box{glm::vec3(1e30f), glm::vec3(1e30f)});
                    MotionBounds bounds;
                    solver.step(state, scene.settings, 7u, nullptr, sim.substep_length(), scene.settings.springs.damping, &boxes,
                                 motion ? &bounds : nullptr);
                    INFO(cols << " x " << cols << ", " << FastSolver::kernel_name() << ", " << threads
                              << " thread(s), substep " << substep);
                    const std::size_t bytes = state.size() * sizeof(double);  // NaN != NaN: compare the bits
                    CHECK(std::memcmp(state.position.x.data(), plain.position.x.data(), bytes) == 0);
                    CHECK(std::memcmp(state.position.y.data(), plain.position.y.data(), bytes) == 0);
                    CHECK(std::memcmp(state.position.z.data(), plain.position.z.data(), bytes) == 0);
                    REQUIRE(boxes.size() + 1 == start.size());
                    int mismatched = 0;
                    std::size_t first = boxes.size();
                    for (std::size_t k = 0; k < boxes.size(); ++k) {
                        const Box want = particle_bounds(state.position, start[k], start[k + 1]);
                        if (!(boxes[k].lo == want.lo && boxes[k].hi == want.hi)) {
                            ++mismatched;
                            first = std::min(first, k);
                        }
                    }
                    INFO("first mismatched block " << first);
                    CHECK(mismatched == 0);
                    // The held particle's box keeps its y and z.
                    const std::size_t block = 5 * blocks_per_row(cols);
                    CHECK(boxes[block].lo.y <= float(state.position.y[held]));
                    CHECK(boxes[block].hi.y >= float(state.position.y[held]));
                }
                // The NaN has reached other particles, which the boxes above left out.
                std::size_t nan = 0;
                for (std::size_t i = 0; i < state.size(); ++i) nan += std::isnan(state.position.x[i]) ? 1 : 0;
                CHECK(nan > 1);
            }
        }
    });
}
