// The projective integrator (projective.hpp): BDF2 minimised by quasi-Newton iterations on a prefactorised
// matrix. Its order and stability are checked with the other integrators (test_integrators.cpp); here, what is
// its own: the iterations converge, the matrix follows the pins and the settings, copies step alike, and a
// damped cloth settles where Verlet settles.
#include "support.hpp"

#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

using namespace clothsim;

namespace {

// Stiff cotton hanging from two corners (stretch 4000 N/m), 12 x 12, one 1/60 s substep a step: about 30 times
// Verlet's step limit.
Scene stiff_hanging(int iterations) {
    Scene s = load_scene("stiff-hanging");
    apply_override(s, "cloth.rows=12");
    apply_override(s, "cloth.cols=12");
    s.settings.integration.integrator = Integrator::Projective;
    s.settings.integration.substeps = 1;
    s.settings.integration.iterations = iterations;
    s.settings.integration.tolerance = 1e-12f;
    return s;
}

}  // namespace

TEST_CASE("projective: more iterations lower the residual and approach the converged step", "[projective]") {
    MassSpring converged = build_simulation(stiff_hanging(400));
    converged.run_steps(20);
    INFO("converged: " << converged.last_solver_iterations() << " iterations, residual "
                       << converged.last_solver_residual());
    REQUIRE(converged.last_solver_residual() < 1e-5);
    double previous_residual = INFINITY, previous_distance = INFINITY, at_4 = 0.0;
    for (int iterations : {1, 4, 16, 64}) {
        MassSpring sim = build_simulation(stiff_hanging(iterations));
        sim.run_steps(20);
        const double distance = test::largest_distance(sim, converged);
        INFO(iterations << " iterations: residual " << sim.last_solver_residual() << ", " << distance
                        << " m from the converged run");
        CHECK(sim.last_solver_iterations() == iterations);
        CHECK(sim.last_solver_residual() < previous_residual);
        CHECK(distance < previous_distance);
        previous_residual = sim.last_solver_residual();
        previous_distance = distance;
        if (iterations == 4) at_4 = distance;
    }
    // Measured: 0.49, 0.19, 0.064, 0.016 m from the converged run after 20 steps at 1, 4, 16, 64 iterations: the
    // slow convergence on stiff cloth that docs/STIFF_CLOTH.md quantifies.
    CHECK(previous_distance < 0.15 * at_4);
}

TEST_CASE("projective: the tolerance stops the iterations early", "[projective]") {
    Scene s = stiff_hanging(1000);
    s.settings.integration.tolerance = 1e-3f;
    MassSpring sim = build_simulation(s);
    sim.run_steps(10);
    CHECK(sim.last_solver_residual() <= 1e-3);
    CHECK(sim.last_solver_iterations() < 1000);
    CHECK(sim.last_solver_iterations() > 1);
}

TEST_CASE("projective: freeing a pin or changing the stiffness refactorises the matrix", "[projective]") {
    SECTION("a freed pin swings down with the cloth") {
        MassSpring sim = build_simulation(stiff_hanging(50));
        sim.run_steps(30);
        REQUIRE(sim.state().pinned[0] == kPinned);
        const glm::vec3 pin = sim.position(0);
        sim.set_pinned(0, false);
        sim.run_steps(30);
        CHECK(sim.all_finite());
        CHECK(sim.position(0).y < pin.y - 0.05f);
    }
    SECTION("softer springs stretch further") {
        Scene s = stiff_hanging(50);
        s.settings.springs.damping = 5.0f;
        MassSpring stiff = build_simulation(s);
        stiff.run_steps(30);
        MassSpring soft = stiff;
        test::edit_settings(soft, [](SimulationSettings& edit) { edit.springs.structural *= 0.01f; });
        stiff.run_steps(120);
        soft.run_steps(120);
        double soft_length = 0.0, stiff_length = 0.0;
        for (const Spring& sp : stiff.topology().springs) {
            if (sp.kind != SpringKind::Structural) continue;
            stiff_length += glm::length(stiff.state().position.get(sp.b) - stiff.state().position.get(sp.a));
            soft_length += glm::length(soft.state().position.get(sp.b) - soft.state().position.get(sp.a));
        }
        CHECK(soft_length > 1.003 * stiff_length);
    }
}

TEST_CASE("projective: a copy steps exactly as the original", "[projective]") {
    MassSpring sim = build_simulation(stiff_hanging(8));
    sim.run_steps(5);
    MassSpring copy = sim;  // shares the factorisation, copies BDF2's history
    sim.run_steps(5);
    copy.run_steps(5);
    CHECK(test::bit_identical(sim, copy));
}

TEST_CASE("projective: a damped cloth settles where Verlet settles", "[projective]") {
    // The settled shape is the static equilibrium of the same springs: every integrator must find it.
    Scene s = stiff_hanging(30);
    s.settings.springs.damping = 5.0f;  // the slowest swing decays as exp(-2.5 t)
    s.settings.solver.sleep_speed = 0.0f;
    MassSpring projective = build_simulation(s);
    projective.run_steps(420);
    s.settings.integration.integrator = Integrator::Verlet;
    s.settings.integration.substeps = 40;  // 0.6 of the 12 x 12 cloth's critical substep
    MassSpring verlet = build_simulation(s);
    verlet.run_steps(420);
    REQUIRE(verlet.all_finite());
    INFO("kinetic energy: projective " << projective.energy().kinetic << " J, verlet " << verlet.energy().kinetic);
    CHECK(projective.energy().kinetic < 1e-8);
    CHECK(verlet.energy().kinetic < 1e-8);
    CHECK(test::largest_distance(projective, verlet) < 1e-4);  // 0.1 mm on a 0.6 m cloth
}

TEST_CASE("projective: at small substeps the line search still finds steps, so the iterations reach the tolerance",
          "[projective]") {
    // At 256 substeps per 1/60 s step, g's decrease per iteration falls below its round-off (g holds the springs'
    // whole energy) while the residual is still far above 1e-7: a line search by g's decrease alone stops there
    // (measured: a relative residual up to 6.4e-6 after 100 iterations); the slope test of the approximate Wolfe
    // conditions carries the iterations on to the tolerance.
    Scene s = load_scene("hanging");
    apply_override(s, "cloth.rows=16");
    apply_override(s, "cloth.cols=16");
    s.settings.colliders.shapes.clear();
    s.settings.integration.integrator = Integrator::Projective;
    s.settings.integration.substeps = 256;
    s.settings.integration.iterations = 100;
    s.settings.integration.tolerance = 1e-7f;
    MassSpring sim = build_simulation(s);
    double worst = 0.0;
    int most = 0;
    for (int k = 0; k < 4 * 256; ++k) {
        sim.substep();
        worst = std::max(worst, sim.last_solver_residual());
        most = std::max(most, sim.last_solver_iterations());
    }
    INFO("worst relative residual " << worst << ", most iterations " << most);
    REQUIRE(sim.all_finite());
    CHECK(worst <= 1e-7);
    CHECK(most < 100);
}
