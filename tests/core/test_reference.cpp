// The double-precision reference solution and what the accuracy study claims for the float simulation.
#include "support.hpp"

#include "clothsim/reference.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace clothsim;

namespace {

// The accuracy study's smooth scene (bench/work_precision.cpp): hanging, 16 x 16, no ground, no damping.
Scene smooth_scene() {
    Scene s = load_scene("hanging");
    s.cloth.rows = s.cloth.cols = 16;
    s.settings.colliders.ground.enabled = false;
    s.settings.springs.damping = 0.0f;
    return s;
}

ErrorNorms float_error(Scene s, Integrator integrator, double h, double duration,
                       const std::vector<glm::dvec3>& reference) {
    s.settings.integration.integrator = integrator;
    s.settings.integration.dt = static_cast<float>(h);
    s.settings.integration.substeps = 1;
    MassSpring sim = build_simulation(s);
    for (long long i = 0; i < std::llround(duration / h); ++i) sim.step();
    return relative_error(sim, reference, cloth_size(s));
}

}  // namespace

TEST_CASE("reference double RK4 matches the analytic damped oscillator to 1e-9", "[reference]") {
    const double m = 0.1, k = 100.0, c = 2.0, rest = 0.5;
    Scene s = test::chain(2, static_cast<float>(rest), static_cast<float>(m), static_cast<float>(k));
    s.pins.particles = {{0, 0}};
    s.settings.springs.damping = static_cast<float>(c);
    // Start stretched by giving the free particle a velocity instead (the builder places it at rest length):
    // u(0) = 0, u'(0) = v0 gives u(t) = v0 e^{-gamma t} sin(wd t) / wd.
    s.cloth.velocity = {0.0f, -0.3f, 0.0f};
    const double w = std::sqrt(k / m), gamma = 0.5 * c, wd = std::sqrt(w * w - gamma * gamma);
    const double t = 0.05;  // about a quarter period: the largest swing
    const std::vector<glm::dvec3> x = run_double_rk4(s, t, 1e-5);
    const double exact = -0.3 * std::exp(-gamma * t) * std::sin(wd * t) / wd;
    // The builder's positions are float, so the start itself is only float-exact: compare the displacement.
    const double start = static_cast<double>(build_simulation(s).position(1).y);
    INFO("displacement " << (x[1].y - start) << " m, exact " << exact << " m");
    CHECK(std::fabs(exact) > 0.005);  // a real swing, not a particle at rest
    CHECK(std::fabs((x[1].y - start) - exact) < 1e-9);
}

TEST_CASE("reference halving check converges below 1e-9 on the smooth scene", "[reference]") {
    const Reference ref = reference_solution(smooth_scene(), 0.25, 5e-4, 1e-9, 8);
    INFO("substep " << ref.substep << ", last halving changed positions by " << ref.halving_change);
    CHECK(ref.converged);
    CHECK(ref.halving_change < 1e-9);
    CHECK(ref.halving_change > 0.0);
}

TEST_CASE("reference float simulation stays within the error the work-precision study claims", "[reference]") {
    // docs/ACCURACY.md (smooth scene): Verlet about 2.7e-4 at h = 1/512 s and 8.7e-5 at 1/1024 s; RK4
    // 2.1e-5 at 1/512 s, and a float floor of a few 1e-6. Claimed here with a margin of 2 at T = 0.25 s.
    const Scene s = smooth_scene();
    const Reference ref = reference_solution(s, 0.25, 5e-4, 1e-9, 8);
    REQUIRE(ref.converged);
    const ErrorNorms verlet_coarse = float_error(s, Integrator::Verlet, 1.0 / 512, 0.25, ref.positions);
    const ErrorNorms verlet_fine = float_error(s, Integrator::Verlet, 1.0 / 1024, 0.25, ref.positions);
    const ErrorNorms rk4 = float_error(s, Integrator::Rk4, 1.0 / 512, 0.25, ref.positions);
    INFO("verlet " << verlet_coarse.max << ", " << verlet_fine.max << "; rk4 " << rk4.max);
    CHECK(verlet_coarse.max < 5.4e-4);
    CHECK(verlet_fine.max < 1.8e-4);
    CHECK(verlet_fine.max < 0.5 * verlet_coarse.max);  // still converging: second order above the floor
    CHECK(rk4.max < 4.2e-5);
    CHECK(rk4.rms <= rk4.max);
}
