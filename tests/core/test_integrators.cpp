// The integrators against the analytic (damped) oscillator: observed convergence orders by halving the step,
// the size of the error, switching integrators mid-run, and what each does with pins, colliders and stiff
// springs.
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "clothsim/stability.hpp"
#include "collision/colliders.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <numbers>

using namespace clothsim;

namespace {

// One particle of mass m on a spring k, the other end pinned; displaced by A and released at rest. Returns
// the largest |u(t) - u_exact(t)| over two periods, for `substeps_per_period` substeps per period.
double oscillator_error(Integrator integrator, int substeps_per_period, double c) {
    const double m = 0.1, k = 100.0, amplitude = 0.05, rest = 0.5;
    const double w = std::sqrt(k / m), gamma = 0.5 * c, wd = std::sqrt(w * w - gamma * gamma);
    const double period = 2.0 * std::numbers::pi / w, h = period / substeps_per_period;
    Scene s = test::chain(2, static_cast<float>(rest), static_cast<float>(m), static_cast<float>(k));
    s.pins.particles = {{0, 0}};
    s.settings.springs.damping = static_cast<float>(c);
    s.settings.integration.dt = static_cast<float>(h);
    s.settings.integration.integrator = integrator;
    s.settings.integration.tolerance = 1e-7f;
    s.settings.integration.iterations = 100;
    MassSpring sim = build_simulation(s);
    sim.set_particle(1, {0.0f, static_cast<float>(-rest - amplitude), 0.0f}, glm::vec3(0.0f));
    double worst = 0.0;
    const long long steps = std::llround(2.0 * period / h);
    for (long long i = 0; i < steps; ++i) {
        sim.substep();
        const double t = sim.time();
        const double exact = amplitude * std::exp(-gamma * t) * (std::cos(wd * t) + gamma / wd * std::sin(wd * t));
        worst = std::max(worst, std::fabs(-(double(sim.position(1).y) + rest) - exact));
    }
    return worst;
}

// Observed order from errors at n and 2n substeps per period.
double order(Integrator integrator, int n, double c) {
    return std::log2(oscillator_error(integrator, n, c) / oscillator_error(integrator, 2 * n, c));
}

}  // namespace

TEST_CASE("integrators observed convergence orders: symplectic Euler 1, RK4 4, implicit Euler 1, projective 2",
          "[integrators]") {
    for (double c : {0.0, 2.0}) {
        INFO("damping " << c << " 1/s");
        CHECK(order(Integrator::Verlet, 50, c) == Approx(2.0).margin(0.1));
        CHECK(order(Integrator::SymplecticEuler, 100, c) == Approx(1.0).margin(0.15));
        CHECK(order(Integrator::SymplecticEuler, 200, c) == Approx(1.0).margin(0.1));
        // RK4's error reaches float round-off (1e-7 of 0.5 m) below about 50 substeps per period.
        CHECK(order(Integrator::Rk4, 12, c) == Approx(4.0).margin(0.3));
        CHECK(order(Integrator::Rk4, 25, c) == Approx(4.0).margin(0.3));
        CHECK(order(Integrator::ImplicitEuler, 400, c) == Approx(1.0).margin(0.15));
        CHECK(order(Integrator::Projective, 50, c) == Approx(2.0).margin(0.15));  // BDF2
        CHECK(order(Integrator::Projective, 100, c) == Approx(2.0).margin(0.1));
    }
}

TEST_CASE("integrators match the analytic damped oscillator within their expected error", "[integrators]") {
    // At 100 substeps per period (w h = 0.063) and amplitude 5 cm: a first-order method errs by O(w h) of the
    // amplitude, second order by O((w h)^2), fourth by O((w h)^4).
    const double amplitude = 0.05;
    for (double c : {0.0, 2.0, 8.0}) {
        INFO("damping " << c << " 1/s");
        CHECK(oscillator_error(Integrator::Verlet, 100, c) < 0.01 * amplitude);
        CHECK(oscillator_error(Integrator::SymplecticEuler, 100, c) < 0.06 * amplitude);
        CHECK(oscillator_error(Integrator::Rk4, 100, c) < 1e-4 * amplitude);
        CHECK(oscillator_error(Integrator::ImplicitEuler, 100, c) < 0.4 * amplitude);
        CHECK(oscillator_error(Integrator::Xpbd, 100, c) < 0.4 * amplitude);
        CHECK(oscillator_error(Integrator::Projective, 100, c) < 0.03 * amplitude);
    }
}

TEST_CASE("integrators XPBD approaches the spring model as the substeps grow", "[integrators]") {
    double previous = INFINITY;
    for (int n : {50, 100, 200, 400, 800}) {
        const double e = oscillator_error(Integrator::Xpbd, n, 0.0);
        INFO(n << " substeps per period: error " << e);
        CHECK(e < 0.6 * previous);  // roughly halves with the substep
        previous = e;
    }
    CHECK(previous < 0.005 * 0.05 * 10);  // under 2.5 mm of the 5 cm swing at 800 substeps per period
}

TEST_CASE("integrators XPBD treats springs above its rigid stiffness alike: one substep leaves alpha / (w + alpha)"
          " of the stretch", "[integrators]") {
    // One spring, its top end pinned, its free end (0.1 kg, w = 10 /kg) 5 cm past its rest length and at rest;
    // no gravity, no damping. One substep predicts nothing and projects once: the stretch left is
    // alpha / (w + alpha), alpha = 1 / (k h^2), which is 1/11 at xpbd_rigid_stiffness and 1/101 at 10 times it.
    const double h = 1e-3, w = 10.0, stretch = 0.05;
    auto stretch_left = [&](double k) {
        Scene s = test::chain(2, 0.5f, 0.1f, static_cast<float>(k));
        s.pins.particles = {{0, 0}};
        s.settings.forces.gravity = glm::vec3(0.0f);
        s.settings.springs.damping = 0.0f;
        s.settings.integration.integrator = Integrator::Xpbd;
        s.settings.integration.dt = static_cast<float>(h);
        s.settings.integration.substeps = 1;
        MassSpring sim = build_simulation(s);
        sim.set_particle(1, {0.0f, static_cast<float>(-0.5 - stretch), 0.0f}, glm::vec3(0.0f));
        sim.substep();
        return (glm::length(glm::dvec3(sim.position(1) - sim.position(0))) - 0.5) / stretch;
    };
    const double k = xpbd_rigid_stiffness(w, h);
    CHECK(k == Approx(1e6));  // 10 / (10 /kg x (1 ms)^2)
    CHECK(stretch_left(k) == Approx(1.0 / 11.0).epsilon(1e-3));
    CHECK(stretch_left(10.0 * k) == Approx(1.0 / 101.0).epsilon(1e-2));
    CHECK(stretch_left(0.1 * k) == Approx(1.0 / 2.0).epsilon(1e-3));  // below it, k shows
}

TEST_CASE("integrators switching mid-run keeps position and velocity", "[integrators]") {
    Scene s = test::chain(1, 1.0f, 1.0f, 0.0f);
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.integration.dt = 0.001f;
    MassSpring sim = build_simulation(s);
    for (Integrator next : {Integrator::Rk4, Integrator::SymplecticEuler, Integrator::ImplicitEuler,
                            Integrator::Xpbd, Integrator::Projective, Integrator::Verlet}) {
        sim.run_steps(100);
        test::edit_settings(sim, [&](SimulationSettings& edit) { edit.integration.integrator = next; });
    }
    sim.run_steps(100);  // 0.7 s of free fall through six integrators
    CHECK(sim.velocities()[0].y == Approx(-9.81 * 0.7).epsilon(2e-3));
    CHECK(sim.position(0).y == Approx(-0.5 * 9.81 * 0.49).epsilon(5e-3));
}

TEST_CASE("integrators implicit Euler and projective stay stable far beyond the explicit step limit",
          "[integrators]") {
    Scene s = per_spring_scene("hanging");
    s.cloth.rows = s.cloth.cols = 16;
    s.settings.integration.substeps = 1;  // h = 16.7 ms: about 20x Verlet's limit for these springs
    s.settings.springs.damping = 0.0f;
    s.settings.integration.integrator = Integrator::Verlet;
    MassSpring verlet = build_simulation(s);
    verlet.run_steps(60);
    CHECK_FALSE(verlet.all_finite());  // explicit: blows up
    for (Integrator integrator : {Integrator::ImplicitEuler, Integrator::Projective}) {
        INFO("integrator " << static_cast<int>(integrator));
        s.settings.integration.integrator = integrator;
        MassSpring implicit = build_simulation(s);
        const double e0 = implicit.energy().total();
        implicit.run_steps(60);
        CHECK(implicit.all_finite());
        CHECK(implicit.energy().total() < e0);  // backward Euler and BDF2 dissipate at large steps
        CHECK(implicit.last_solver_iterations() > 0);
    }
}

TEST_CASE("integrators all keep pins fixed and particles outside the colliders", "[integrators]") {
    for (Integrator integrator : {Integrator::SymplecticEuler, Integrator::Rk4, Integrator::ImplicitEuler,
                                  Integrator::Xpbd, Integrator::Projective}) {
        Scene s = per_spring_scene("drape-sphere");  // 38 substeps a step keep implicit Euler's 90 steps short
        s.cloth.rows = s.cloth.cols = 20;
        s.pins.particles = {{0, 0}};
        s.settings.integration.integrator = integrator;
        MassSpring sim = build_simulation(s);
        const glm::vec3 pin = sim.position(0);
        sim.run_steps(90);
        INFO("integrator " << static_cast<int>(integrator));
        CHECK(sim.all_finite());
        CHECK(sim.position(0) == pin);
        for (std::size_t i = 1; i < sim.particle_count(); ++i) {
            CHECK(signed_distance(test::sphere(s.settings.colliders), sim.position(i)) >= 0.0f);
            CHECK(signed_distance(test::plane(s.settings.colliders), sim.position(i)) >= 0.0f);
        }
    }
}

TEST_CASE("integrators XPBD reports its constraint residual: none for one spring, some for a cloth", "[integrators]") {
    // One spring, one free end: a single projection solves C + alpha~ lambda = 0 exactly.
    Scene chain = test::chain(2, 0.5f, 0.1f, 100.0f);
    chain.pins.particles = {{0, 0}};
    chain.settings.integration.integrator = Integrator::Xpbd;
    chain.settings.integration.substeps = 4;
    MassSpring one = build_simulation(chain);
    one.set_particle(1, {0.0f, -0.55f, 0.0f}, glm::vec3(0.0f));
    one.run_steps(3);
    CHECK(one.last_solver_iterations() == 1);
    CHECK(one.last_solver_residual() < 1e-9);
    // A cloth: each projection disturbs its neighbours, so one Gauss-Seidel pass leaves a residual.
    Scene s = per_spring_scene("hanging");
    s.cloth.rows = s.cloth.cols = 12;
    test::collider(s.settings.colliders, "ground").enabled = false;
    s.settings.integration.integrator = Integrator::Xpbd;
    MassSpring cloth = build_simulation(s);
    cloth.run_steps(10);
    INFO("residual " << cloth.last_solver_residual());
    CHECK(cloth.last_solver_residual() > 1e-3);
    CHECK(cloth.last_solver_residual() < 1.0);
}

TEST_CASE("integrators read integration.tolerance and integration.iterations exactly where settings.hpp says they do",
          "[integrators]") {
    // The panel dims the two fields for an integrator that does not read them (uses_tolerance, uses_iterations):
    // a run that changes only the field differs exactly when the integrator reads it.
    for (Integrator integrator : {Integrator::Verlet, Integrator::SymplecticEuler, Integrator::Rk4,
                                  Integrator::ImplicitEuler, Integrator::Xpbd, Integrator::Projective}) {
        Scene s = per_spring_scene("hanging");
        s.cloth.rows = s.cloth.cols = 10;
        s.settings.integration.integrator = integrator;
        s.settings.integration.substeps = 4;
        s.settings.integration.tolerance = 1e-9f;
        s.settings.integration.iterations = 40;
        MassSpring base = build_simulation(s);
        Scene looser = s;  // stops earlier where the tolerance is read
        looser.settings.integration.tolerance = 1e-2f;
        Scene fewer = s;  // stops earlier where the iterations are read
        fewer.settings.integration.iterations = 2;
        MassSpring by_tolerance = build_simulation(looser);
        MassSpring by_iterations = build_simulation(fewer);
        base.run_steps(5);
        by_tolerance.run_steps(5);
        by_iterations.run_steps(5);
        INFO(integrator_names()[static_cast<int>(integrator)]);
        CHECK(test::bit_identical(base, by_tolerance) == !uses_tolerance(integrator));
        CHECK(test::bit_identical(base, by_iterations) == !uses_iterations(integrator));
        CHECK((base.last_solver_iterations() > 0) == reports_solve(integrator));
    }
}
