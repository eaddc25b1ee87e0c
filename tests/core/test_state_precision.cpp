// The state's precision (state.hpp): more substeps never make a run less accurate. A float state lost the
// substep's update to the position's rounding (docs/ACCURACY.md: error growing past ~150 substeps per step,
// XPBD frozen at 272); these tests fail on such a state.
#include "clothsim/reference.hpp"
#include "clothsim/scene.hpp"

#include "per_spring_scenes.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <vector>

using namespace clothsim;

namespace {

constexpr float kStep = 1.0f / 60.0f;  // s: the bundled scenes' step

// The smooth scene of the accuracy study: hanging with the ground off (no contact), at side x side.
Scene smooth_scene(int side) {
    Scene s = per_spring_scene("hanging");
    s.cloth.rows = s.cloth.cols = side;
    test::collider(s.settings.colliders, "ground").enabled = false;
    s.settings.integration.dt = kStep;
    s.settings.integration.tolerance = 1e-6f;
    return s;
}

MassSpring run(Scene s, Integrator integrator, int substeps, int steps) {
    s.settings.integration.integrator = integrator;
    s.settings.integration.substeps = substeps;
    MassSpring sim = build_simulation(s);
    sim.run_steps(steps);
    return sim;
}

glm::dvec3 centroid(const MassSpring& sim) {
    glm::dvec3 sum(0.0);
    for (std::size_t i = 0; i < sim.particle_count(); ++i) sum += sim.state().position.get(i);
    return sum / static_cast<double>(sim.particle_count());
}

}  // namespace

TEST_CASE("state precision: a particle at rest under gravity at 1e5 substeps per second falls g t^2 / 2",
          "[precision]") {
    // One free particle at 1.6 m, where a float position's ulp (1.2e-7 m) is 120 times the first substep's
    // displacement g h^2 = 9.8e-10 m.
    Scene s = test::chain(1, 1.0f, 0.01f, 0.0f);
    s.cloth.origin = {0.0f, 1.6f, 0.0f};
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.integration.dt = 0.01f;
    s.settings.integration.substeps = 1000;  // h = 1e-5 s
    const int steps = 50;                    // t = 0.5 s: 5e4 substeps
    for (Integrator integrator : {Integrator::Verlet, Integrator::SymplecticEuler, Integrator::Rk4,
                                  Integrator::ImplicitEuler, Integrator::Xpbd}) {
        INFO(integrator_names()[static_cast<int>(integrator)]);
        const MassSpring sim = run(s, integrator, s.settings.integration.substeps, steps);
        const double h = sim.substep_length();
        const double n = static_cast<double>(steps) * s.settings.integration.substeps;
        const double t = n * h;
        // Verlet (second-order start) and RK4 are exact for a constant acceleration; the first-order
        // integrators (v += h g, then x += h v) give g h^2 n (n + 1) / 2 exactly.
        const bool exact = integrator == Integrator::Verlet || integrator == Integrator::Rk4;
        const double expected = exact ? 0.5 * 9.81 * t * t : 0.5 * 9.81 * h * h * n * (n + 1.0);
        const double fallen = double(1.6f) - sim.state().position.y[0];
        INFO("fell " << fallen << " m, expected " << expected << " m");
        CHECK(std::fabs(fallen - expected) <= 1e-6 * expected);
        CHECK(sim.state().position.x[0] == 0.0);
    }
}

TEST_CASE("state precision: xpbd released flat at 272, 544 and 4096 substeps per step falls like verlet",
          "[precision]") {
    const Scene s = smooth_scene(16);
    const int steps = 30;  // 0.5 s
    for (int substeps : {272, 544, 4096}) {
        INFO(substeps << " substeps per step");
        const MassSpring xpbd = run(s, Integrator::Xpbd, substeps, steps);
        const MassSpring verlet = run(s, Integrator::Verlet, substeps, steps);
        const glm::dvec3 start = centroid(build_simulation(s));
        const glm::dvec3 a = centroid(xpbd), b = centroid(verlet);
        INFO("centroid drop: xpbd " << start.y - a.y << " m, verlet " << start.y - b.y << " m");
        CHECK(start.y - b.y > 0.1);  // it fell
        CHECK(glm::length(a - b) < 1e-3);
        CHECK(xpbd.energy().kinetic > 0.1 * verlet.energy().kinetic);
    }
}

TEST_CASE("state precision: past its floor, more substeps keep verlet, rk4 and xpbd within 2x of the floor",
          "[precision]") {
    const Scene s = smooth_scene(8);
    const int steps = 15;  // T = 0.25 s
    // The reference at the simulation's own end time (15 float steps of 1/60 s).
    const double end = steps * static_cast<double>(kStep);
    const Reference ref = reference_solution(s, end, 2e-4, 1e-11, 8);
    REQUIRE(ref.converged);
    for (Integrator integrator : {Integrator::Verlet, Integrator::Rk4, Integrator::Xpbd}) {
        const char* name = integrator_names()[static_cast<int>(integrator)].data();
        std::vector<double> error;
        std::vector<int> substeps;
        for (int n = 1; n <= 512; n *= 2) {
            const MassSpring sim = run(s, integrator, n, steps);
            substeps.push_back(n);
            error.push_back(sim.all_finite() ? relative_error(sim, ref.positions, cloth_size(s)).max : INFINITY);
        }
        std::size_t at = 0;
        for (std::size_t i = 1; i < error.size(); ++i) {
            if (error[i] < error[at]) at = i;
        }
        const double floor = error[at];
        const double beyond = relative_error(run(s, integrator, 8 * substeps[at], steps), ref.positions,
                                             cloth_size(s)).max;
        INFO(name << ": floor " << floor << " at " << substeps[at] << " substeps per step, " << beyond << " at "
                  << 8 * substeps[at]);
        for (std::size_t i = at; i < error.size(); ++i) CHECK(error[i] <= 2.0 * floor);
        CHECK(beyond <= 2.0 * floor);
        if (integrator != Integrator::Xpbd) CHECK(floor <= 3e-6);
    }
}
