// Stability: the predicted limits (Gershgorin and plane-wave bounds, critical substep) against hand-derived
// numbers and against measured blow-ups, auto_substeps, the guard that rolls back and doubles substeps,
// and extreme inputs that must either run to a finite state or be rejected with a clear SceneError.
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "collision/colliders.hpp"
#include "clothsim/stability.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace clothsim;
using Catch::Contains;

namespace {

// A square n x n cloth, 1 m wide and 0.5 kg, floating free: no pins, no gravity, no ground, no damping;
// springs k (structural), k/10 (shear), k/40 (bending); one substep per step.
Scene free_grid(int n, float k) {
    Scene s;
    s.cloth.rows = n;
    s.cloth.cols = n;
    s.pins.preset = PinPreset::None;
    s.settings.springs = {glm::vec2(k), 0.1f * k, glm::vec2(0.025f * k), 0.0f};
    s.settings.forces.gravity = {0.0f, 0.0f, 0.0f};
    test::collider(s.settings.colliders, "ground").enabled = false;
    s.settings.integration.substeps = 1;
    s.settings.solver.threads = 1;  // no spinning worker threads when the machine is busy
    return s;
}

// The scene's simulation with a random velocity (each component uniform in [-speed, speed]) on every
// particle: every mode, the fastest included, starts with some energy.
MassSpring with_random_velocity(const Scene& scene, float speed, unsigned seed = 1) {
    const MassSpring built = build_simulation(scene);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-speed, speed);
    std::vector<glm::vec3> v(built.particle_count());
    for (glm::vec3& vi : v) vi = {u(rng), u(rng), u(rng)};
    return MassSpring(built.topology(), built.state(), built.settings(), v);
}

bool finite_energy(const MassSpring& sim) { return std::isfinite(sim.energy().total()); }

// Whether the run blew up: a non-finite position or energy, or energy grown far beyond the start.
bool blown_up(const MassSpring& sim, double initial_energy) {
    if (!sim.all_finite()) return true;
    const double e = sim.energy().total();
    return !std::isfinite(e) || e > 1e3 * (std::fabs(initial_energy) + 1.0);
}

std::string build_error(const Scene& scene) {
    try {
        build_simulation(scene);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "(no SceneError thrown)";
}

std::string override_error(Scene& scene, const std::string& assignment) {
    try {
        apply_override(scene, assignment);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "(no SceneError thrown)";
}

// Sets integration.substeps from the predicted limit (safety 0.5) and runs `steps` steps.
void run_auto(MassSpring& sim, long long steps, float safety = 0.5f) {
    sim.set_substeps(auto_substeps(stability_limit(sim), sim.settings().integration.dt, safety, 1));
    sim.run_steps(steps);
}

}  // namespace

// ---- 1. The numbers of stability_limit. ----

TEST_CASE("stability limit of one particle on one spring is the Gershgorin bound 2k/m", "[stability]") {
    const double k = 100.0;
    Scene s = test::chain(2, 0.5f, 0.1f, static_cast<float>(k));
    s.pins.particles = {{0, 0}};
    const MassSpring sim = build_simulation(s);
    REQUIRE(sim.spring_count() == 1);
    const double m = sim.state().mass[1];

    const StabilityLimit limit = stability_limit(sim);
    CHECK_FALSE(limit.unconditionally_stable);
    CHECK(limit.omega_gershgorin * limit.omega_gershgorin == Approx(2.0 * k / m).epsilon(1e-9));
    CHECK(limit.critical_substep == Approx(2.0 / limit.omega_gershgorin).epsilon(1e-9));
    CHECK(limit.critical_substep == Approx(2.0 / std::sqrt(2.0 * k / m)).epsilon(1e-9));
    // The overload on the parts gives the same numbers.
    const StabilityLimit parts = stability_limit(sim.topology(), sim.state(), sim.settings());
    CHECK(parts.critical_substep == limit.critical_substep);
    CHECK(parts.omega_gershgorin == limit.omega_gershgorin);
}

TEST_CASE("stability damping leaves verlet's critical substep at w h = 2", "[stability]") {
    // clothsim's central-difference damping cancels out of Verlet's limit (verlet.hpp, docs/STABILITY.md).
    Scene s = test::chain(2, 0.5f, 0.1f, 100.0f);
    s.pins.particles = {{0, 0}};
    for (double c : {0.0, 0.5, 50.0, 1e4}) {
        s.settings.springs.damping = static_cast<float>(c);
        const StabilityLimit limit = stability_limit(build_simulation(s));
        INFO("damping " << c << " 1/s");
        CHECK(limit.omega_gershgorin * limit.critical_substep == Approx(2.0).epsilon(1e-9));
        CHECK(limit.omega_plane_wave * limit.plane_wave_substep == Approx(2.0).epsilon(1e-9));
    }
}

TEST_CASE("stability damping shrinks symplectic euler's critical substep to w h = 2 sqrt(1 - c h/2)",
          "[stability]") {
    Scene s = test::chain(2, 0.5f, 0.1f, 100.0f);
    s.pins.particles = {{0, 0}};
    s.settings.integration.integrator = Integrator::SymplecticEuler;
    const double undamped = stability_limit(build_simulation(s)).critical_substep;
    double previous = undamped;
    for (double c : {0.5, 5.0, 50.0, 1e4}) {
        s.settings.springs.damping = static_cast<float>(c);
        const StabilityLimit limit = stability_limit(build_simulation(s));
        const double h = limit.critical_substep;
        const double w = limit.omega_gershgorin;
        INFO("damping " << c << " 1/s: critical substep " << h << " s (undamped " << undamped << " s)");
        CHECK(h > 0.0);
        CHECK(h < previous);  // more damping, smaller limit
        CHECK(c * h < 2.0);   // |1 - c h| < 1
        CHECK(w * h == Approx(2.0 * std::sqrt(1.0 - 0.5 * c * h)).epsilon(1e-6));
        const double hp = limit.plane_wave_substep;
        CHECK(limit.omega_plane_wave * hp == Approx(2.0 * std::sqrt(1.0 - 0.5 * c * hp)).epsilon(1e-6));
        previous = h;
    }
}

TEST_CASE("stability plane-wave bound on a grid is 4 (k_struct + k_shear + k_bend) / m", "[stability]") {
    Scene s;  // the default cloth, 16 x 16
    s.cloth.rows = s.cloth.cols = 16;
    const MassSpring sim = build_simulation(s);
    const SpringSettings& k = s.settings.springs;
    const double m = sim.state().mass[0];
    REQUIRE(m == Approx(0.5 / 256.0).epsilon(1e-6));
    const double sum_k = double(k.structural.x) + double(k.shear) + double(k.bending.x);

    const StabilityLimit limit = stability_limit(sim);
    CHECK(limit.omega_plane_wave * limit.omega_plane_wave == Approx(4.0 * sum_k / m).epsilon(1e-9));
    CHECK(limit.omega_gershgorin >= limit.omega_plane_wave);
    // An interior particle has 4 springs of each kind: the Gershgorin row sum is 2 x 4 x sum_k.
    CHECK(limit.omega_gershgorin * limit.omega_gershgorin == Approx(8.0 * sum_k / m).epsilon(1e-9));
    // A looser bound on omega gives a smaller substep.
    CHECK(limit.plane_wave_substep >= limit.critical_substep);
    // Undamped, both substeps are 2 / omega.
    s.settings.springs.damping = 0.0f;
    const StabilityLimit undamped = stability_limit(build_simulation(s));
    CHECK(undamped.critical_substep == Approx(2.0 / undamped.omega_gershgorin).epsilon(1e-9));
    CHECK(undamped.plane_wave_substep == Approx(2.0 / undamped.omega_plane_wave).epsilon(1e-9));
}

TEST_CASE("stability rk4 reaches sqrt(2) times verlet's substep, implicit euler and xpbd have no limit",
          "[stability]") {
    Scene s = free_grid(8, 1000.0f);
    const MassSpring verlet = build_simulation(s);
    const StabilityLimit v = stability_limit(verlet);
    REQUIRE(std::isfinite(v.critical_substep));

    s.settings.integration.integrator = Integrator::Rk4;
    const StabilityLimit rk4 = stability_limit(build_simulation(s));
    CHECK(rk4.critical_substep == Approx(std::sqrt(2.0) * v.critical_substep).epsilon(1e-9));
    CHECK(rk4.plane_wave_substep == Approx(std::sqrt(2.0) * v.plane_wave_substep).epsilon(1e-9));
    CHECK(rk4.omega_gershgorin == Approx(v.omega_gershgorin).epsilon(1e-12));
    CHECK_FALSE(rk4.unconditionally_stable);

    s.settings.integration.integrator = Integrator::SymplecticEuler;
    const StabilityLimit se = stability_limit(build_simulation(s));
    CHECK(se.critical_substep == Approx(v.critical_substep).epsilon(1e-12));
    CHECK_FALSE(se.unconditionally_stable);

    for (Integrator i : {Integrator::ImplicitEuler, Integrator::Xpbd}) {
        s.settings.integration.integrator = i;
        const StabilityLimit limit = stability_limit(build_simulation(s));
        CHECK(limit.unconditionally_stable);
        CHECK(std::isinf(limit.critical_substep));
        CHECK(std::isinf(limit.plane_wave_substep));
        CHECK(auto_substeps(limit, 1.0f / 60.0f, 0.5f, 3) == 3);
    }
}

// ---- 2. The predicted limit against measured blow-ups. ----

TEST_CASE("stability verlet is stable at 0.9 x the critical substep and blows up at 3 x", "[stability]") {
    for (int n : {8, 16}) {
        for (float k : {100.0f, 1e4f, 1e6f}) {
            Scene s = free_grid(n, k);
            const double critical = stability_limit(build_simulation(s)).critical_substep;
            REQUIRE(std::isfinite(critical));
            for (double factor : {0.9, 3.0}) {
                s.settings.integration.dt = static_cast<float>(factor * critical);
                MassSpring sim = with_random_velocity(s, 0.1f);
                const double e0 = sim.energy().total();
                REQUIRE(std::isfinite(e0));
                sim.run_steps(2000);
                INFO(n << " x " << n << ", k = " << k << " N/m, substep " << factor << " x critical (" << critical
                       << " s): finite " << sim.all_finite() << ", energy " << e0 << " J -> "
                       << sim.energy().total() << " J");
                if (factor < 1.0) {
                    CHECK(sim.all_finite());
                    CHECK(sim.energy().total() < 10.0 * std::fabs(e0) + 1.0);
                    CHECK(max_strain(sim) < 1.0);
                } else {
                    CHECK(blown_up(sim, e0));
                }
            }
        }
    }
}

TEST_CASE("stability verlet is stable at 0.9 x the critical substep with damping", "[stability]") {
    for (float c : {1.0f, 100.0f, 1e4f}) {
        Scene s = free_grid(8, 1e4f);
        s.settings.springs.damping = c;
        const StabilityLimit limit = stability_limit(build_simulation(s));
        s.settings.integration.dt = static_cast<float>(0.9 * limit.critical_substep);
        MassSpring sim = with_random_velocity(s, 0.1f);
        const double e0 = sim.energy().total();
        sim.run_steps(2000);
        INFO("damping " << c << " 1/s, substep " << s.settings.integration.dt << " s");
        CHECK(sim.all_finite());
        CHECK(sim.energy().total() <= e0 + 1e-9);  // damped: energy does not grow
    }
}

namespace {

// One particle on one spring, the other end pinned: w^2 = k/m exactly (half the Gershgorin bound). Displaced
// 5 cm and run `substeps` substeps of h; returns the final |displacement|, or infinity when non-finite.
double oscillator_amplitude(Integrator integrator, double c, double h, int substeps) {
    Scene s = test::chain(2, 0.5f, 0.1f, 100.0f);
    s.pins.particles = {{0, 0}};
    s.settings.springs.damping = static_cast<float>(c);
    s.settings.integration.integrator = integrator;
    s.settings.integration.dt = static_cast<float>(h);
    MassSpring sim = build_simulation(s);
    sim.set_particle(1, {0.0f, -0.55f, 0.0f}, glm::vec3(0.0f));
    // The amplitude: the largest |u| over the last 100 substeps (an unstable run ends in a bounded, irregular
    // swing through the pin, where a single sample can be anywhere).
    double amplitude = 0.0;
    for (int i = 0; i < substeps; ++i) {
        sim.substep();
        if (i >= substeps - 100) amplitude = std::max(amplitude, std::fabs(sim.state().position.y[1] + 0.5));
    }
    if (!sim.all_finite()) return std::numeric_limits<double>::infinity();
    return amplitude;
}

double oscillator_omega() {
    Scene s = test::chain(2, 0.5f, 0.1f, 100.0f);
    return std::sqrt(100.0 / double(build_simulation(s).state().mass[1]));
}

}  // namespace

TEST_CASE("stability damped verlet's measured limit is w h = 2 whatever the damping", "[stability]") {
    const double w = oscillator_omega();
    for (double c : {0.0, 20.0, 200.0}) {
        const double stable = oscillator_amplitude(Integrator::Verlet, c, 1.96 / w, 3000);
        const double unstable = oscillator_amplitude(Integrator::Verlet, c, 2.04 / w, 3000);
        INFO("damping " << c << " 1/s: |u| = " << stable << " m at w h = 1.96, " << unstable << " m at 2.04");
        CHECK(stable <= 0.05 + 1e-4);
        // Grown at least fourfold (beyond u = 0.5 m the spring folds through its pinned end, which caps a
        // finite amplitude there).
        CHECK(unstable > 0.2);
    }
}

TEST_CASE("stability damped symplectic euler's measured limit is w h = 2 sqrt(1 - c h/2)", "[stability]") {
    const double w = oscillator_omega();
    for (double c : {0.0, 10.0, 30.0}) {
        // Solve w h = 2 sqrt(1 - c h / 2) for h: w^2 h^2 + 2 c h - 4 = 0.
        const double h = (-2.0 * c + std::sqrt(4.0 * c * c + 16.0 * w * w)) / (2.0 * w * w);
        const double stable = oscillator_amplitude(Integrator::SymplecticEuler, c, 0.97 * h, 3000);
        const double unstable = oscillator_amplitude(Integrator::SymplecticEuler, c, 1.03 * h, 3000);
        INFO("damping " << c << " 1/s, limit h = " << h << " s: |u| = " << stable << " m at 0.97 h, " << unstable
                        << " m at 1.03 h");
        // Stable: bounded by the invariant ellipse of undamped symplectic Euler started at rest from u0,
        // v^2 + w^2 u^2 - h w^2 u v = w^2 u0^2, whose largest |u| is u0 / sqrt(1 - (w h / 2)^2) (damping only
        // shrinks it).
        const double wh = w * 0.97 * h;
        CHECK(stable <= 0.05 / std::sqrt(1.0 - 0.25 * wh * wh) + 1e-4);
        CHECK(unstable > 0.2);
    }
}

// ---- 3. auto_substeps. ----

TEST_CASE("stability auto_substeps keeps dt / substeps below safety x critical and the run stable",
          "[stability]") {
    const float dt = 1.0f / 60.0f;
    Scene s = free_grid(16, 1e5f);
    s.settings.integration.dt = dt;
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.springs.damping = 0.2f;
    s.pins.preset = PinPreset::TopCorners;
    const StabilityLimit limit = stability_limit(build_simulation(s));
    for (float safety : {0.5f, 0.9f}) {
        const int n = auto_substeps(limit, dt, safety, 1);
        INFO("safety " << safety << ": " << n << " substeps, critical " << limit.critical_substep << " s");
        CHECK(n == static_cast<int>(std::ceil(double(dt) / (double(safety) * limit.critical_substep))));
        CHECK(double(dt) / n <= double(safety) * limit.critical_substep * (1.0 + 1e-12));
        CHECK(double(dt) / (n - 1) > double(safety) * limit.critical_substep);
        CHECK(n > 1);

        s.settings.integration.substeps = n;
        MassSpring sim = with_random_velocity(s, 0.1f);
        const double e0 = sim.energy().total();
        sim.run_steps(30);
        CHECK(sim.all_finite());
        CHECK(sim.energy().total() < 10.0 * std::fabs(e0) + 1.0);
        CHECK(max_strain(sim) < 1.0);
    }
    // At least `minimum`, and at least 1.
    const int needed = auto_substeps(limit, dt, 0.9f, 1);
    CHECK(auto_substeps(limit, dt, 0.9f, needed + 7) == needed + 7);
    CHECK(auto_substeps(limit, dt, 0.9f, 0) == needed);
    StabilityLimit none;
    none.critical_substep = std::numeric_limits<double>::infinity();
    CHECK(auto_substeps(none, dt, 0.9f, 0) == 1);
    CHECK(auto_substeps(none, dt, 0.9f, 4) == 4);
    // At most kMaxSubsteps, the largest a scene file may hold (so what is chosen can be saved and loaded).
    StabilityLimit tiny;
    tiny.critical_substep = 1e-12;
    CHECK(auto_substeps(tiny, dt, 0.9f, 1) == kMaxSubsteps);
}

// ---- 4. run_guarded. ----

namespace {

// The hanging cloth (per spring, as these figures were measured) made 2500 times stiffer (structural 1e6 N/m).
Scene stiff_hanging(int n, int substeps) {
    Scene s = per_spring_scene("hanging");
    apply_override(s, "cloth.rows=" + std::to_string(n));
    apply_override(s, "cloth.cols=" + std::to_string(n));
    apply_override(s, "springs.structural=1e6");
    apply_override(s, "integration.substeps=" + std::to_string(substeps));
    apply_override(s, "integration.dt=0.016666667");
    s.settings.solver.threads = 1;
    return s;
}

long long count_lines(const std::string& text) {
    long long lines = 0;
    for (char ch : text) lines += ch == '\n';
    return lines;
}

}  // namespace

TEST_CASE("stability run_guarded rolls back a blow-up and doubles the substeps", "[stability]") {
    // The 32 x 32 hanging cloth at 1e6 N/m needs about 1070 substeps per frame by the Gershgorin bound and
    // 760 by the plane-wave one; it starts at 25 and blows up in the first frame.
    const Scene s = stiff_hanging(32, 25);
    MassSpring sim = build_simulation(s);
    const double e0 = sim.energy().total();
    {
        MassSpring plain = sim;
        plain.run_steps(1);
        CHECK((!plain.all_finite() || max_strain(plain) > 10.0));
    }

    std::string log;
    const bool ok = run_guarded(sim, 12, GuardSettings{}, log);
    INFO(log);
    CHECK(ok);
    CHECK_THAT(log, Contains("rolled back"));
    CHECK_THAT(log, Contains("it held at"));
    CHECK(sim.all_finite());
    CHECK(finite_energy(sim));
    CHECK(max_strain(sim) <= GuardSettings{}.max_strain);
    CHECK(max_strain(sim) < 0.5);
    CHECK(sim.energy().total() < 2.0 * std::fabs(e0) + 1.0);  // recovered, not merely finite
    CHECK(sim.time() == Approx(12.0 * s.settings.integration.dt).epsilon(1e-4));
    // Doubled from 25 (one line per step that needed it); it settled at or below the plane-wave limit.
    const int substeps = sim.settings().integration.substeps;
    CHECK(substeps > 25);
    CHECK(substeps % 25 == 0);
    CHECK(((substeps / 25) & (substeps / 25 - 1)) == 0);
    CHECK(count_lines(log) >= 1);
    CHECK(double(s.settings.integration.dt) / substeps <= stability_limit(sim).plane_wave_substep);
}

TEST_CASE("stability run_guarded recovers from one substep per frame with a tight strain bound", "[stability]") {
    // One substep per frame at 1e6 N/m: the first frame only falls (strain 5e-5), the second stretches a
    // spring 160% (energy 8 J -> 3e9 J). A 50% strain bound catches that frame, so the state it rolls
    // back to is still sound and enough doublings recover the run.
    const Scene s = stiff_hanging(8, 1);
    MassSpring sim = build_simulation(s);
    const double e0 = sim.energy().total();
    GuardSettings guard;
    guard.max_strain = 0.5f;
    guard.max_retries = 12;
    std::string log;
    const bool ok = run_guarded(sim, 30, guard, log);
    INFO(log);
    CHECK(ok);
    CHECK_THAT(log, Contains("rolled back"));
    CHECK_THAT(log, Contains("it held at"));
    CHECK(sim.all_finite());
    CHECK(max_strain(sim) <= guard.max_strain);
    CHECK(sim.energy().total() < 2.0 * std::fabs(e0) + 1.0);
    const int substeps = sim.settings().integration.substeps;
    CHECK((substeps & (substeps - 1)) == 0);  // doubled from 1
    CHECK(double(s.settings.integration.dt) / substeps <= stability_limit(sim).plane_wave_substep);
    CHECK(sim.time() == Approx(30.0 * s.settings.integration.dt).epsilon(1e-4));
}

TEST_CASE("stability run_guarded with the default bounds never leaves a NaN", "[stability]") {
    // The same, with the default 1000% bound: the second frame (strain 160%, energy 3e9 J) passes the check,
    // and the state the guard later rolls back to is already wrecked. Whatever it returns, the state it
    // leaves is finite and within the bound.
    MassSpring sim = build_simulation(stiff_hanging(8, 1));
    std::string log;
    const GuardSettings guard;
    const bool ok = run_guarded(sim, 30, guard, log);
    INFO(log);
    CHECK_THAT(log, Contains("rolled back"));
    CHECK(sim.all_finite());
    CHECK(finite_energy(sim));
    CHECK(max_strain(sim) <= guard.max_strain);
    if (!ok) CHECK_THAT(log, Contains("stopped at the last good state"));
}

TEST_CASE("stability run_guarded with no retries stops at the last good state", "[stability]") {
    const Scene s = stiff_hanging(8, 1);
    MassSpring sim = build_simulation(s);

    GuardSettings guard;
    guard.max_retries = 0;
    std::string log;
    const bool ok = run_guarded(sim, 30, guard, log);
    INFO(log);
    CHECK_FALSE(ok);
    CHECK_THAT(log, Contains("stopped at the last good state"));
    // One line, saying what cannot be stepped and what it would take.
    CHECK(count_lines(log) == 1);
    const double needed = std::ceil(s.settings.integration.dt / stability_limit(sim).critical_substep);
    CHECK_THAT(log, Contains("the springs (structural k = ") && Contains("need " + std::to_string(int(needed)) + " substeps per step"));
    CHECK(sim.all_finite());
    CHECK(finite_energy(sim));
    CHECK(max_strain(sim) <= guard.max_strain);
    CHECK(sim.settings().integration.substeps == 1);
    // Rolled back to a whole step before the failing one.
    CHECK(sim.time() < 30.0 * s.settings.integration.dt);
    const double steps = sim.time() / s.settings.integration.dt;
    CHECK(steps == Approx(std::round(steps)).margin(1e-3));

    // The state it stopped at is the one plain stepping reaches after as many steps.
    MassSpring plain = build_simulation(s);
    plain.run_steps(std::llround(steps));
    CHECK(plain.positions() == sim.positions());
}

TEST_CASE("stability run_guarded leaves a stable run untouched", "[stability]") {
    Scene s = free_grid(8, 400.0f);
    s.settings.integration.substeps = 25;
    MassSpring guarded = with_random_velocity(s, 0.1f);
    MassSpring plain = guarded;
    std::string log;
    CHECK(run_guarded(guarded, 20, GuardSettings{}, log));
    CHECK(log.empty());
    plain.run_steps(20);
    CHECK(guarded.positions() == plain.positions());
    CHECK(guarded.settings().integration.substeps == 25);
}

TEST_CASE("stability max_strain is the largest relative stretch and infinite for NaN", "[stability]") {
    Scene s = test::chain(3, 0.5f, 0.1f, 100.0f);
    MassSpring sim = build_simulation(s);
    CHECK(max_strain(sim) == Approx(0.0).margin(1e-6));
    sim.set_particle(2, {0.0f, -1.5f, 0.0f}, glm::vec3(0.0f));  // second spring 0.5 -> 1.0 m
    CHECK(max_strain(sim) == Approx(1.0).epsilon(1e-6));
    sim.set_particle(1, {0.0f, NAN, 0.0f}, glm::vec3(0.0f));
    CHECK(std::isinf(max_strain(sim)));
}

// ---- 5. Extreme inputs: run to a finite state or be rejected with a message. ----

TEST_CASE("stability stiffness 1e9 ends finite under the guard and with auto_substeps", "[stability]") {
    Scene s;
    s.cloth.rows = s.cloth.cols = 6;
    apply_override(s, "springs.structural=1e9");
    apply_override(s, "springs.shear=1e9");
    apply_override(s, "springs.bending=1e9");
    apply_override(s, "integration.substeps=1");
    {
        MassSpring sim = build_simulation(s);
        GuardSettings guard;
        guard.max_retries = 16;
        std::string log;
        const bool ok = run_guarded(sim, 3, guard, log);
        INFO(log);
        CHECK(ok);
        CHECK(sim.all_finite());
        CHECK(finite_energy(sim));
        CHECK(max_strain(sim) <= guard.max_strain);
    }
    {
        MassSpring sim = build_simulation(s);
        run_auto(sim, 2);
        INFO(sim.settings().integration.substeps << " substeps");
        CHECK(sim.all_finite());
        CHECK(finite_energy(sim));
        CHECK(max_strain(sim) < 1.0);
    }
}

TEST_CASE("stability a 0.1 s step ends finite under the guard", "[stability]") {
    Scene s;
    s.cloth.rows = s.cloth.cols = 16;
    apply_override(s, "integration.dt=0.1");
    apply_override(s, "integration.substeps=1");
    s.settings.solver.threads = 1;
    for (int retries : {6, 10}) {
        MassSpring sim = build_simulation(s);
        GuardSettings guard;
        guard.max_retries = retries;
        std::string log;
        const bool ok = run_guarded(sim, 10, guard, log);
        INFO(retries << " retries: " << log << "ok " << ok << ", t = " << sim.time() << " s, substeps "
                     << sim.settings().integration.substeps << ", energy " << sim.energy().total() << " J");
        CHECK(sim.all_finite());
        CHECK(finite_energy(sim));
        CHECK(max_strain(sim) <= guard.max_strain);
        if (ok) {
            CHECK(sim.time() == Approx(1.0).epsilon(1e-5));
        } else {
            CHECK_THAT(log, Contains("stopped at the last good state"));
        }
    }
}

TEST_CASE("stability damping 0 and the maximum 1e4 run finite", "[stability]") {
    for (const char* damping : {"springs.damping=0", "springs.damping=1e4"}) {
        Scene s;
        s.cloth.rows = s.cloth.cols = 12;
        apply_override(s, damping);
        MassSpring sim = build_simulation(s);
        const StabilityLimit limit = stability_limit(sim);
        INFO(damping << ": critical substep " << limit.critical_substep << " s, substep " << sim.substep_length());
        CHECK(limit.critical_substep > 0.0);
        CHECK(std::isfinite(limit.critical_substep));
        sim.run_steps(60);
        CHECK(sim.all_finite());
        CHECK(finite_energy(sim));
        CHECK(max_strain(sim) < 1.0);
    }
    // Damping beyond the maximum is rejected, naming the field and the range.
    Scene s;
    const std::string message = override_error(s, "springs.damping=2e4");
    CHECK_THAT(message, Contains("springs.damping"));
    CHECK_THAT(message, Contains("allowed"));
}

TEST_CASE("stability gravity 1e4 m/s^2 ends finite", "[stability]") {
    Scene s;
    s.cloth.rows = s.cloth.cols = 12;
    s.settings.solver.threads = 1;
    apply_override(s, "forces.gravity=[0,-10000,0]");
    REQUIRE(s.settings.forces.gravity.y == -10000.0f);
    for (bool automatic : {false, true}) {
        MassSpring sim = build_simulation(s);
        if (automatic) {
            run_auto(sim, 60);
        } else {
            sim.run_steps(60);  // the scene's 25 substeps
        }
        INFO(sim.settings().integration.substeps << " substeps");
        CHECK(sim.all_finite());
        CHECK(finite_energy(sim));
        // Nothing falls through the ground.
        for (std::size_t i = 0; i < sim.particle_count(); ++i) CHECK(sim.position(i).y >= -1e-3f);
    }
}

TEST_CASE("stability wind 1e3 m/s ends finite under the guard", "[stability]") {
    // Pinned at two corners, 1000 m/s of wind pushes with about 6e5 N against 400 N/m springs: the cloth
    // cannot hold it (strain far above 1000%), and plain stepping ends non-finite. The guard must either run
    // or stop at a finite state.
    for (const char* model : {"triangles", "uniform"}) {
        Scene s;
        s.cloth.rows = s.cloth.cols = 12;
        s.settings.solver.threads = 1;
        apply_override(s, "forces.wind=[0,0,1000]");
        apply_override(s, std::string("forces.wind_model=") + model);
        MassSpring sim = build_simulation(s);
        std::string log;
        GuardSettings guard;
        guard.max_retries = 10;
        const bool ok = run_guarded(sim, 30, guard, log);
        INFO(model << ": " << log);
        CHECK(sim.all_finite());
        CHECK(finite_energy(sim));
        CHECK(max_strain(sim) <= guard.max_strain);
        if (!ok) CHECK_THAT(log, Contains("stopped at the last good state"));
    }
}

TEST_CASE("stability wind 1e3 m/s on a free cloth runs finite at the auto substeps", "[stability]") {
    // The wind's drag has a rate of about 2 x drag x area x |wind| / m (here ~1e3 1/s), so explicit
    // stepping needs substeps of ~1 ms or less; stability_limit includes it (it once did not: auto
    // substeps chose 17 per frame and the run went non-finite within 30 frames).
    Scene s;
    s.cloth.rows = s.cloth.cols = 12;
    s.pins.preset = PinPreset::None;
    s.settings.solver.threads = 1;
    apply_override(s, "forces.wind=[0,0,1000]");
    {
        Scene enough = s;
        enough.settings.integration.substeps = 100;
        MassSpring sim = build_simulation(enough);
        sim.run_steps(30);
        REQUIRE(sim.all_finite());  // the model itself is fine here
    }
    MassSpring sim = build_simulation(s);
    run_auto(sim, 30);
    INFO(sim.settings().integration.substeps << " substeps");
    CHECK(sim.all_finite());
}

TEST_CASE("stability tiny cloths 1x1, 1xN, Nx1 and 2x2 run finite", "[stability]") {
    for (auto [rows, cols] : {std::pair{1, 1}, std::pair{1, 7}, std::pair{7, 1}, std::pair{2, 2}}) {
        for (PinPreset pins : {PinPreset::None, PinPreset::TopCorners}) {
            Scene s;
            s.cloth.rows = rows;
            s.cloth.cols = cols;
            s.pins.preset = pins;
            s.cloth.velocity = {0.3f, 0.0f, 0.2f};
            MassSpring sim = build_simulation(s);
            const StabilityLimit limit = stability_limit(sim);
            INFO(rows << " x " << cols << ", pins " << int(pins) << ": critical " << limit.critical_substep);
            CHECK(limit.critical_substep > 0.0);
            CHECK(auto_substeps(limit, s.settings.integration.dt, 0.5f, 1) >= 1);
            sim.run_steps(60);
            CHECK(sim.all_finite());
            CHECK(finite_energy(sim));
            for (std::size_t i = 0; i < sim.particle_count(); ++i) CHECK(sim.position(i).y >= -1e-3f);
            if (rows * cols == 1) {
                CHECK(sim.spring_count() == 0);
                if (pins == PinPreset::None) CHECK(std::isinf(limit.critical_substep));
            }
        }
    }
}

TEST_CASE("stability coincident particles from a 0.001 m cloth run finite", "[stability]") {
    SECTION("many particles on a 1 mm cloth") {
        Scene s;
        apply_override(s, "cloth.rows=48");
        apply_override(s, "cloth.cols=48");
        apply_override(s, "cloth.size=0.001");
        MassSpring sim = build_simulation(s);
        run_auto(sim, 10);
        INFO(sim.settings().integration.substeps << " substeps");
        CHECK(sim.all_finite());
        CHECK(finite_energy(sim));
    }
    SECTION("a 1 mm cloth far from the origin, where float rounding merges neighbours") {
        Scene s;
        apply_override(s, "cloth.rows=16");
        apply_override(s, "cloth.cols=16");
        apply_override(s, "cloth.size=0.001");
        apply_override(s, "cloth.origin=[10000, 10000, 0]");  // float spacing 1e-3 m there
        MassSpring sim = build_simulation(s);
        bool zero_rest = false;
        for (const Spring& sp : sim.topology().springs) zero_rest |= sp.rest_length == 0.0f;
        CHECK(zero_rest);  // some neighbours start at the same point
        const StabilityLimit limit = stability_limit(sim);
        CHECK(limit.critical_substep > 0.0);
        run_auto(sim, 10);
        CHECK(sim.all_finite());
        CHECK(finite_energy(sim));
        CHECK(std::isfinite(max_strain(sim)));
    }
    SECTION("a 1 x 2048 row 1 mm long") {
        Scene s;
        apply_override(s, "cloth.rows=1");
        apply_override(s, "cloth.cols=2048");
        apply_override(s, "cloth.size=0.001");
        apply_override(s, "pins=\"none\"");
        MassSpring sim = build_simulation(s);
        run_auto(sim, 2);
        CHECK(sim.all_finite());
        CHECK(finite_energy(sim));
    }
}

TEST_CASE("stability a hand-built topology with zero-length springs runs finite", "[stability]") {
    // Three particles at one point: a spring of rest length 0 (pulls toward coincidence) and one of rest
    // length 0.1 m that starts at length 0 (no direction to push along), plus a normal spring.
    const State state = test::free_particles({{0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f},
                                              {0.2f, 1.0f, 0.0f}},
                                             0.01f);
    Topology topology;
    topology.springs = {{0, 1, 0.0f, SpringKind::Structural},
                        {1, 2, 0.1f, SpringKind::Structural},
                        {2, 3, 0.2f, SpringKind::Shear}};
    SimulationSettings settings;
    test::collider(settings.colliders, "ground").enabled = false;
    settings.forces.gravity = {0.0f, 0.0f, 0.0f};
    MassSpring sim(topology, state, settings, {});
    REQUIRE_FALSE(sim.fast_solver_available());
    CHECK(max_strain(sim) == Approx(0.0).margin(1e-6));  // rest-length-0 springs are skipped; 0 / 0.1 - 1 = -1
    const StabilityLimit limit = stability_limit(sim);
    CHECK(std::isfinite(limit.critical_substep));
    CHECK(limit.critical_substep > 0.0);
    sim.run_steps(60);
    CHECK(sim.all_finite());
    CHECK(finite_energy(sim));
    CHECK(sim.position(0) == sim.position(1));  // nothing moved: no force on coincident particles

    // Set one moving: the zero-length spring pulls it back, the rest follow; all stays finite.
    sim.set_particle(0, {0.0f, 1.0f, 0.0f}, {1.0f, 0.5f, 0.0f});
    run_auto(sim, 60);
    CHECK(sim.all_finite());
    CHECK(finite_energy(sim));
    CHECK(std::isfinite(max_strain(sim)));
}

TEST_CASE("stability every particle pinned: nothing moves and there is no limit", "[stability]") {
    SECTION("pins as a list of every [row, col]") {
        Scene s;
        s.cloth.rows = s.cloth.cols = 4;
        std::string pins = "pins=[";
        for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c) {
                pins += '[';
                pins += std::to_string(r);
                pins += ',';
                pins += std::to_string(c);
                pins += "],";
            }
        }
        pins.back() = ']';
        apply_override(s, pins);
        s.pins.preset = PinPreset::None;
        MassSpring sim = build_simulation(s);
        const std::vector<glm::vec3> start = sim.positions();
        const StabilityLimit limit = stability_limit(sim);
        CHECK(std::isinf(limit.critical_substep));
        CHECK(auto_substeps(limit, s.settings.integration.dt, 0.5f, 1) == 1);
        sim.run_steps(30);
        CHECK(sim.positions() == start);
        CHECK(sim.energy().kinetic == 0.0);
    }
    SECTION("left-edge pins on a one-column cloth") {
        Scene s;
        apply_override(s, "cloth.rows=9");
        apply_override(s, "cloth.cols=1");
        apply_override(s, "pins=left-edge");
        MassSpring sim = build_simulation(s);
        const std::vector<glm::vec3> start = sim.positions();
        CHECK(std::isinf(stability_limit(sim).critical_substep));
        std::string log;
        CHECK(run_guarded(sim, 30, GuardSettings{}, log));
        CHECK(log.empty());
        CHECK(sim.positions() == start);
    }
}

TEST_CASE("stability nothing pinned: the cloth falls to the ground and stays finite", "[stability]") {
    Scene s;
    s.cloth.rows = s.cloth.cols = 12;
    s.pins.preset = PinPreset::None;
    MassSpring sim = build_simulation(s);
    sim.run_steps(90);
    CHECK(sim.all_finite());
    CHECK(finite_energy(sim));
    float lowest = INFINITY;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        CHECK(sim.position(i).y >= -1e-4f);
        lowest = std::min(lowest, sim.position(i).y);
    }
    CHECK(lowest < 0.01f);  // it reached the ground within 1.5 s
}

TEST_CASE("stability a sphere around pinned particles: pinned stay put, free ones are pushed out",
          "[stability]") {
    Scene s;
    s.cloth.rows = s.cloth.cols = 12;  // top corners (row 0) pinned at (-0.5, 1.5, 0) and (0.5, 1.5, 0)
    test::collider(s.settings.colliders, "sphere") = Collider{SphereCollider{{-0.5f, 1.5f, 0.0f}, 0.25f}, 0.3f, true, {}};
    MassSpring sim = build_simulation(s);
    const glm::vec3 pin0 = sim.position(0), pin1 = sim.position(11);
    REQUIRE(signed_distance(test::sphere(s.settings.colliders), pin0) < 0.0f);
    const float thickness = s.settings.colliders.thickness;
    for (int step = 0; step < 60; ++step) {
        sim.run_steps(1);
        REQUIRE(sim.all_finite());
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            if (sim.particle(i).pinned) continue;
            INFO("step " << step << ", particle " << i);
            CHECK(signed_distance(test::sphere(sim.settings().colliders), sim.position(i)) >= thickness - 1e-4f);
        }
    }
    CHECK(sim.position(0) == pin0);
    CHECK(sim.position(11) == pin1);
    CHECK(finite_energy(sim));
}

TEST_CASE("stability a sphere enclosing the whole cloth pushes every particle to its surface", "[stability]") {
    Scene s;
    s.cloth.rows = s.cloth.cols = 5;  // particle (2, 2) sits exactly at the centre (0, 1, 0)
    s.pins.preset = PinPreset::None;
    s.settings.forces.gravity = {0.0f, 0.0f, 0.0f};
    test::collider(s.settings.colliders, "ground").enabled = false;
    test::collider(s.settings.colliders, "sphere") = Collider{SphereCollider{{0.0f, 1.0f, 0.0f}, 10.0f}, 0.3f, true, {}};
    MassSpring sim = build_simulation(s);
    REQUIRE(sim.position(12) == glm::vec3(0.0f, 1.0f, 0.0f));
    const float surface = 10.0f + s.settings.colliders.thickness;
    for (int step = 0; step < 60; ++step) {
        sim.run_steps(1);
        REQUIRE(sim.all_finite());
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            INFO("step " << step << ", particle " << i);
            CHECK(glm::length(sim.position(i) - glm::vec3(0.0f, 1.0f, 0.0f)) >= surface * (1.0f - 1e-5f));
        }
    }
    CHECK(finite_energy(sim));
}

// ---- The limiters (springs.strain_limit, forces.max_speed). ----

TEST_CASE("stability a strain-limited spring holding a load does not gather speed", "[stability]") {
    // A particle held at the limit must not store speed: when the correction moved the position back but
    // kept `motion`, its velocity grew by g h every substep (-93 m/s and 434 J after 10 s while it sat
    // still), and a cloth under a steady load ran away to NaN.
    Scene s = test::chain(2, 0.5f, 0.1f, 1.0f);  // 1 N/m cannot hold 0.98 N within 10%
    s.pins.particles = {{0, 0}};
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.springs.strain_limit = 0.1f;
    s.settings.integration.substeps = 10;
    MassSpring sim = build_simulation(s);
    sim.run_steps(600);
    INFO("y = " << sim.position(1).y << " m, v = " << sim.velocities()[1].y << " m/s");
    CHECK(max_strain(sim) == Approx(0.1).epsilon(1e-3));  // held at the limit
    CHECK(std::fabs(sim.velocities()[1].y) < 1.0f);
    CHECK(sim.energy().kinetic < 0.1);
}

TEST_CASE("stability max_speed bounds how far a particle moves", "[stability]") {
    // The clamp must shorten the substep's displacement, not only the velocity: scaling `motion` after the
    // position had moved let a particle under g = 1000 m/s^2 with max_speed 1 m/s fall 2.66 m in 1 s.
    Scene s = test::chain(1, 1.0f, 0.1f, 0.0f);
    s.settings.forces.gravity = {0.0f, -1000.0f, 0.0f};
    s.settings.forces.max_speed = 1.0f;
    s.settings.integration.substeps = 10;
    MassSpring sim = build_simulation(s);
    sim.run_steps(60);  // 1 s
    const float fallen = -sim.position(0).y;
    INFO("fell " << fallen << " m in 1 s at max_speed 1 m/s");
    CHECK(fallen <= 1.0f + 1e-3f);
}

TEST_CASE("stability grids beyond kMaxParticles are rejected with the limit in the message", "[stability]") {
    Scene s;
    s.cloth.rows = s.cloth.cols = 2048;
    const std::string message = build_error(s);
    CHECK_THAT(message, Contains("cloth.rows x cloth.cols"));
    CHECK_THAT(message, Contains(std::to_string(2048LL * 2048LL)));
    CHECK_THAT(message, Contains(std::to_string(kMaxParticles)));

    // Through --set: the second override makes the grid too big and leaves the scene unchanged.
    Scene t;
    apply_override(t, "cloth.rows=2048");
    const std::string set_message = override_error(t, "cloth.cols=2048");
    CHECK_THAT(set_message, Contains("cloth.rows x cloth.cols"));
    CHECK_THAT(set_message, Contains(std::to_string(kMaxParticles)));
    CHECK(t.cloth.cols == 32);

    // Exactly kMaxParticles is allowed, one row more is not.
    Scene edge;
    edge.cloth.rows = edge.cloth.cols = 1024;
    REQUIRE(1024LL * 1024LL == kMaxParticles);
    CHECK_NOTHROW(validate(edge));
    edge.cloth.rows = 1025;
    CHECK_THROWS_AS(validate(edge), SceneError);
}

TEST_CASE("stability every bundled scene steps inside its predicted limit", "[stability]") {
    // The scenes' substeps are chosen so the substep is at most 0.7 of the Gershgorin critical substep:
    // safe by the bound, not only in practice (the panel shows it green).
    for (const std::string& name : bundled_scene_names()) {
        const MassSpring sim = build_simulation(load_scene(name));
        const StabilityLimit limit = stability_limit(sim);
        INFO(name << ": substep " << sim.substep_length() << " s, critical " << limit.critical_substep << " s");
        CHECK(sim.substep_length() <= 0.7 * limit.critical_substep);
    }
}

TEST_CASE("stability damping limits the explicit parts of XPBD and RK4, and auto substeps respects it", "[stability]") {
    for (auto [integrator, damping] : {std::pair{Integrator::Xpbd, 3000.0f}, std::pair{Integrator::Rk4, 9000.0f}}) {
        Scene s = load_scene("hanging");
        s.cloth.rows = s.cloth.cols = 12;
        s.settings.integration.integrator = integrator;
        s.settings.springs.damping = damping;
        MassSpring sim = build_simulation(s);
        const StabilityLimit limit = stability_limit(sim);
        INFO("integrator " << int(integrator) << ", damping " << damping << ": critical " << limit.critical_substep);
        CHECK_FALSE(limit.unconditionally_stable);
        CHECK(limit.critical_substep * damping <= 2.785 + 1e-9);
        CHECK(limit.bound == (integrator == Integrator::Xpbd ? StabilityBound::Damping : StabilityBound::Springs));
        sim.set_substeps(auto_substeps(limit, sim.settings().integration.dt, 0.5f));
        sim.run_steps(20);
        CHECK(sim.all_finite());
        CHECK(std::isfinite(sim.energy().total()));
        CHECK(sim.energy().total() < 100.0);
    }
}

TEST_CASE("stability the guard never raises substeps beyond what a scene file may hold", "[stability]") {
    Scene s = per_spring_scene("hanging");  // its springs and mass are edited below
    s.cloth.rows = s.cloth.cols = 4;
    s.settings.springs.structural = glm::vec2(1e9f);
    s.cloth.mass = 0.005f;
    s.settings.integration.substeps = 8000;
    MassSpring sim = build_simulation(s);
    std::string log;
    run_guarded(sim, 2, GuardSettings{}, log);
    INFO(log);
    CHECK(sim.settings().integration.substeps <= kMaxSubsteps);
    CHECK(sim.all_finite());
    Scene saved = s;
    saved.settings.integration.substeps = sim.settings().integration.substeps;
    CHECK_NOTHROW(parse_scene(to_toml(saved), "saved.toml"));  // what "Save scene as" writes loads back
}
