// Position Verlet against analytic solutions: period and order of the spring oscillator (undamped and with
// physical damping), exact free fall, and the order of the energy error.
#include "support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

using namespace clothsim;

namespace {

constexpr double kPi = std::numbers::pi;

// One particle of mass m on a spring of stiffness k, the other end pinned; displaced by A along the spring
// and released at rest. Returns the displacement u(t) sampled every substep h, for `duration` seconds.
struct Oscillator {
    double m = 0.1, k = 100.0, c = 0.0, amplitude = 0.05, rest = 0.5;
    double omega() const { return std::sqrt(k / m); }

    std::vector<double> run(double h, double duration) const {
        Scene s = test::chain(2, static_cast<float>(rest), static_cast<float>(m), static_cast<float>(k));
        s.pins.particles = {{0, 0}};
        s.settings.springs.damping = static_cast<float>(c);
        s.settings.integration.dt = static_cast<float>(h);
        MassSpring sim = build_simulation(s);
        sim.set_particle(1, {0.0f, static_cast<float>(-rest - amplitude), 0.0f}, glm::vec3(0.0f));
        const auto steps = static_cast<long long>(std::llround(duration / h));
        std::vector<double> u;
        u.reserve(steps + 1);
        u.push_back(-(sim.position(1).y + rest));
        for (long long i = 0; i < steps; ++i) {
            sim.substep();
            u.push_back(-(static_cast<double>(sim.position(1).y) + rest));
        }
        return u;
    }

    // u(t) for u(0) = A, u'(0) = 0 with u'' = -omega^2 u - c u'.
    double exact(double t) const {
        const double gamma = 0.5 * c;
        const double wd = std::sqrt(omega() * omega() - gamma * gamma);
        return amplitude * std::exp(-gamma * t) * (std::cos(wd * t) + gamma / wd * std::sin(wd * t));
    }
};

// Mean period from upward zero crossings, located by linear interpolation (its error at a zero crossing is
// O(h^3) because u'' = 0 there without damping, so it does not mask Verlet's O(h^2) phase error).
double measured_period(const std::vector<double>& u, double h) {
    std::vector<double> crossings;
    for (std::size_t i = 1; i < u.size(); ++i) {
        if (u[i - 1] < 0.0 && u[i] >= 0.0) crossings.push_back(h * (double(i - 1) + u[i - 1] / (u[i - 1] - u[i])));
    }
    REQUIRE(crossings.size() >= 3);
    return (crossings.back() - crossings.front()) / double(crossings.size() - 1);
}

double max_error(const Oscillator& o, const std::vector<double>& u, double h) {
    double e = 0.0;
    for (std::size_t i = 0; i < u.size(); ++i) e = std::max(e, std::fabs(u[i] - o.exact(h * double(i))));
    return e;
}

}  // namespace

TEST_CASE("verlet oscillator period equals 2 pi sqrt(m/k) to second order", "[verlet]") {
    const Oscillator o;
    const double period = 2.0 * kPi * std::sqrt(o.m / o.k);
    double previous_error = 0.0;
    for (int n : {40, 80, 160}) {  // substeps per period
        const double h = period / n;
        const double error = std::fabs(measured_period(o.run(h, 6.0 * period), h) - period) / period;
        // Verlet's discrete frequency is (2/h) asin(omega h / 2): relative period error (omega h)^2 / 24.
        const double predicted = std::pow(o.omega() * h, 2) / 24.0;
        INFO("substeps per period " << n << ": relative period error " << error << ", predicted " << predicted);
        CHECK(error == Approx(predicted).epsilon(0.1));
        if (previous_error > 0.0) {
            const double order = std::log2(previous_error / error);
            INFO("observed order " << order);
            CHECK(order == Approx(2.0).margin(0.15));
        }
        previous_error = error;
    }
}

TEST_CASE("verlet trajectory converges at order 2 with and without physical damping", "[verlet]") {
    for (double c : {0.0, 2.0, 8.0}) {
        Oscillator o;
        o.c = c;
        const double period = 2.0 * kPi / o.omega();
        const double e1 = max_error(o, o.run(period / 50, 3.0 * period), period / 50);
        const double e2 = max_error(o, o.run(period / 100, 3.0 * period), period / 100);
        const double e3 = max_error(o, o.run(period / 200, 3.0 * period), period / 200);
        INFO("damping " << c << " 1/s: max errors " << e1 << ", " << e2 << ", " << e3);
        CHECK(e1 < 0.05 * o.amplitude);
        CHECK(std::log2(e1 / e2) == Approx(2.0).margin(0.2));
        CHECK(std::log2(e2 / e3) == Approx(2.0).margin(0.2));
    }
}

TEST_CASE("verlet damped period matches the damped frequency, whatever the step", "[verlet]") {
    Oscillator o;
    o.c = 4.0;
    const double wd = std::sqrt(o.omega() * o.omega() - 0.25 * o.c * o.c);
    const double period = 2.0 * kPi / wd;
    for (int n : {100, 400}) {
        const double h = period / n;
        // With damping u'' != 0 at the crossings; linear interpolation adds O(h^2) too: 1e-3 covers both.
        CHECK(measured_period(o.run(h, 4.0 * period), h) == Approx(period).epsilon(1e-3));
    }
    // The amplitude decays as exp(-c t / 2) whatever the step: compare the envelope after 4 periods.
    for (int n : {50, 200}) {
        const double h = period / n;
        const std::vector<double> u = o.run(h, 4.0 * period);
        CHECK(u.back() == Approx(o.amplitude * std::exp(-0.5 * o.c * 4.0 * period)).epsilon(0.02));
    }
}

TEST_CASE("verlet free fall is exact: x0 + v0 t + g t^2 / 2", "[verlet]") {
    Scene s = test::chain(1, 0.0f, 0.2f, 0.0f);
    s.cloth.origin = {0.5f, 10.0f, -1.0f};
    s.cloth.velocity = {1.5f, 4.0f, -0.5f};
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.integration.dt = 1.0f / 64.0f;
    MassSpring sim = build_simulation(s);
    const glm::dvec3 x0(0.5, 10.0, -1.0), v0(1.5, 4.0, -0.5), g(0.0, -9.81, 0.0);
    for (int i = 1; i <= 128; ++i) {
        sim.substep();
        const double t = sim.time();
        const glm::dvec3 exact = x0 + v0 * t + 0.5 * g * t * t;
        const glm::dvec3 got(sim.position(0));
        REQUIRE(std::fabs(got.x - exact.x) < 1e-5);
        REQUIRE(std::fabs(got.y - exact.y) < 2e-5);
        REQUIRE(std::fabs(got.z - exact.z) < 1e-5);
    }
    // The velocity estimate is exact for constant acceleration too.
    const glm::vec3 v = sim.velocities()[0];
    CHECK(v.y == Approx(4.0 - 9.81 * sim.time()).margin(1e-3));
}

TEST_CASE("verlet energy error of an undamped cloth stays bounded and shrinks 4x when dt halves", "[verlet]") {
    Scene s;
    s.cloth.rows = 8;
    s.cloth.cols = 8;
    s.cloth.mass = 0.2f;
    s.pins.preset = PinPreset::TopCorners;
    s.settings.springs = {glm::vec2(40.0f), 4.0f, glm::vec2(1.0f), 0.0f};
    test::collider(s.settings.colliders, "ground").enabled = false;
    auto drift = [&](int substeps) {
        s.settings.integration.substeps = substeps;
        MassSpring sim = build_simulation(s);
        const double e0 = sim.energy().total();
        double worst = 0.0, last = 0.0;
        for (int step = 0; step < 60; ++step) {  // one simulated second
            sim.run_steps(1);
            last = sim.energy().total() - e0;
            worst = std::max(worst, std::fabs(last));
        }
        return worst;
    };
    const double e1 = drift(4), e2 = drift(8), e3 = drift(16);
    INFO("max |E - E0| over 1 s: " << e1 << ", " << e2 << ", " << e3 << " J");
    CHECK(e1 < 0.01);  // of about 1 J of motion: bounded, no drift
    CHECK(std::log2(e1 / e2) == Approx(2.0).margin(0.3));
    CHECK(std::log2(e2 / e3) == Approx(2.0).margin(0.3));
}
