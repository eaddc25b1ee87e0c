// Settling to rest (settle.hpp): the residual measures what it says, and kinetic damping reaches an equilibrium
// of the model that the dynamics then keep, sooner than the dynamics reach it.
#include "clothsim/scene.hpp"
#include "clothsim/settle.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

using namespace clothsim;

namespace {

// `hanging` at 16 x 16 (the material form: the same fabric), damping 0.2/s: its swing rings for a minute.
Scene small_hanging() {
    Scene scene = load_scene("hanging");
    apply_override(scene, "cloth.rows=16");
    apply_override(scene, "cloth.cols=16");
    return scene;
}

}  // namespace

TEST_CASE("settle: a free-falling cloth's residual is 1 (its weight unbalanced), one lying on the ground 0",
          "[settle]") {
    Scene scene = small_hanging();
    apply_override(scene, "pins=[]");
    MassSpring sim = build_simulation(scene);
    // At rest, released: every particle falls g dt^2 / 2 in the step, less what the damping (0.2/s) takes.
    const Residual falling = equilibrium_residual(sim);
    CHECK(falling.value == Approx(1.0).epsilon(0.005));
    CHECK(falling.value <= 1.0);
    // The same after 0.25 s of falling (0.31 m, above the ground): the residual is measured from rest, whatever
    // the cloth's speed.
    sim.run_steps(15);
    CHECK(equilibrium_residual(sim).value == Approx(falling.value).epsilon(1e-3));
    // Lying on the ground, the contact and friction hold its weight: balanced.
    sim.run_steps(120);
    CHECK(equilibrium_residual(sim).value < 0.01);
    // The state is left as it was.
    const MassSpring before = sim;
    (void)equilibrium_residual(sim);
    CHECK(test::largest_distance(before, sim) == 0.0);
    CHECK(sim.velocities() == before.velocities());
}

TEST_CASE("settle: kinetic damping brings the hanging cloth to rest within 1% of a particle's weight, an "
          "equilibrium the dynamics keep, where the dynamics alone are still far from it",
          "[settle]") {
    const Scene scene = small_hanging();
    MassSpring settling = build_simulation(scene);
    Settler settler;
    long long steps = 0;
    while (!settler.after_step(settling) && steps < 60 * 30) {
        settling.run_steps(1);
        ++steps;
    }
    INFO("settled after " << steps << " steps, residual " << settler.residual().value << ", " << settler.resets()
                          << " resets");
    REQUIRE(settler.settled());
    CHECK(settler.residual().value < 0.01);
    CHECK(settler.resets() > 3);
    REQUIRE(settling.all_finite());
    // Near an equilibrium: a further 2 s of the plain dynamics from there move no particle by more than
    // r g / omega^2, the displacement with which the cloth's softest mode (its sway, about 0.5 Hz) answers a
    // force r m g: 9.9 mm at r = 0.01. A force residual bounds the distance to equilibrium only through the
    // stiffness. Measured 7.3 mm at r = 0.0089: the settle's damping approaches along the softest mode, where a
    // residual stands for the most distance (kinetic damping alone stopped at 1.8 mm, r = 0.0074).
    MassSpring kept = settling;
    kept.run_steps(120);
    const double omega = 2.0 * 3.14159265358979 * 0.5;
    INFO("the dynamics then move it by " << test::largest_distance(kept, settling) << " m");
    CHECK(test::largest_distance(kept, settling) < settler.residual().value * 9.81 / (omega * omega));
    // The dynamics alone, over the same simulated time, are still swinging: residual well above the tolerance.
    MassSpring dynamics = build_simulation(scene);
    dynamics.run_steps(steps);
    const double swinging = equilibrium_residual(dynamics).value;
    MassSpring swung = dynamics;
    swung.run_steps(120);
    INFO("the dynamics' residual after the same time " << swinging << ", and they move "
                                                        << test::largest_distance(swung, dynamics) << " m in the next 2 s");
    CHECK(swinging > 10.0 * settler.options().tolerance);
    CHECK(test::largest_distance(swung, dynamics) > 10.0 * test::largest_distance(kept, settling));
}

TEST_CASE("settle: the settle's damping adds to the scene's on every integrator and path, and leaves the scene's "
          "setting and the residual's measure alone", "[settle]") {
    // The same swing with springs.damping = 4/s, and with 0/s plus the settle's 4/s: the same positions, bit for
    // bit, on every integrator (Verlet on the fast solver and the textbook's, XPBD on the grid's form too).
    for (Integrator integrator : {Integrator::Verlet, Integrator::SymplecticEuler, Integrator::Rk4,
                                  Integrator::ImplicitEuler, Integrator::Xpbd, Integrator::Projective}) {
        for (SolverMethod method : {SolverMethod::Fast, SolverMethod::Textbook}) {
            INFO(integrator_info(integrator).name << ", method " << static_cast<int>(method));
            Scene scene = small_hanging();
            scene.settings.integration.integrator = integrator;
            scene.settings.solver.method = method;
            scene.settings.springs.damping = 4.0f;
            MassSpring scenes = build_simulation(scene);
            scene.settings.springs.damping = 0.0f;
            MassSpring settles = build_simulation(scene);
            settles.set_settle_damping(4.0);
            CHECK(settles.damping_rate() == 4.0);
            scenes.run_steps(20);
            settles.run_steps(20);
            CHECK(test::largest_distance(scenes, settles) == 0.0);
            CHECK(settles.settings().springs.damping == 0.0f);  // the scene's setting is not touched
        }
    }
    // The damping itself: a particle falling from rest reaches v = g / c (1 - exp(-c t)).
    Scene drop = test::chain(1, 1.0f, 1.0f, 0.0f);
    drop.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    drop.settings.springs.damping = 0.0f;
    drop.settings.integration.dt = 0.001f;
    MassSpring falling = build_simulation(drop);
    falling.set_settle_damping(3.0);
    falling.run_steps(500);
    CHECK(falling.velocities()[0].y == Approx(-9.81 / 3.0 * (1.0 - std::exp(-1.5))).epsilon(1e-4));
    // The residual is the scene's: a free-falling cloth's is 1 with or without the settle's damping on it.
    Scene free = small_hanging();
    apply_override(free, "pins=[]");
    MassSpring plain = build_simulation(free);
    MassSpring damped = build_simulation(free);
    damped.set_settle_damping(20.0);
    CHECK(equilibrium_residual(damped).value == equilibrium_residual(plain).value);
    CHECK_THROWS_AS(damped.set_settle_damping(-1.0), std::invalid_argument);
    CHECK_THROWS_AS(damped.set_settle_damping(std::nan("")), std::invalid_argument);
    CHECK(damped.damping_rate() == 20.0 + free.settings.springs.damping);
}

TEST_CASE("settle: the settle damps the cloth itself only once the fall is over, is off once settled, and settles "
          "the hanging cloth in fewer steps than kinetic damping alone", "[settle]") {
    const Scene scene = small_hanging();
    const SettleOptions options;
    MassSpring sim = build_simulation(scene);
    Settler settler(options);
    long long steps = 0;
    double largest_before = 0.0;  // the largest residual measured while the damping was off
    while (!settler.after_step(sim) && steps < 60 * 30) {
        // The cloth carries the settle's damping exactly while the settler says it is on.
        REQUIRE(sim.settle_damping() == (settler.damping() ? settler.damping_rate() : 0.0));
        if (!settler.damping()) largest_before = std::max(largest_before, settler.residual().value);
        if (settler.damping() && settler.damping_since() == sim.time()) {
            CHECK(settler.residual().value < options.damping_below);  // it went on at a check under the threshold
        }
        sim.run_steps(1);
        ++steps;
    }
    REQUIRE(settler.settled());
    CHECK(settler.damping());
    CHECK(settler.damping_since() > 0.0);  // the fall ran without it
    CHECK(largest_before >= options.damping_below);
    CHECK(sim.settle_damping() == 0.0);  // off once settled: the cloth goes on with the scene's damping
    CHECK(sim.damping_rate() == scene.settings.springs.damping);
    // Kinetic damping alone (measured: 858 steps against 468).
    MassSpring kinetic = build_simulation(scene);
    Settler kinetic_only(SettleOptions{.damping_max = 0.0});
    long long kinetic_steps = 0;
    while (!kinetic_only.after_step(kinetic) && kinetic_steps < 60 * 30) {
        REQUIRE(kinetic.settle_damping() == 0.0);
        kinetic.run_steps(1);
        ++kinetic_steps;
    }
    REQUIRE(kinetic_only.settled());
    INFO(steps << " steps with the settle's damping, " << kinetic_steps << " with kinetic damping alone");
    CHECK(!kinetic_only.damping());
    CHECK(steps < 0.7 * kinetic_steps);
}

TEST_CASE("settle: the settle's damping is critical for the slowest mode, 2 omega, estimated from the motion "
          "between checks", "[settle]") {
    // One particle on a spring of k = 10 N/m below a pin, 0.1 kg, under gravity: one mode, omega = 10 rad/s. The
    // Rayleigh quotient of any motion is omega^2, so the settle's damping is 2 omega = 20/s (the residual's step
    // from rest moves the particle (1 - cos(omega dt)) / omega^2 a, within 0.23% of a dt^2 / 2 at omega dt = 1/6).
    Scene s = test::chain(2, 0.5f, 0.1f, 10.0f);
    s.pins.particles = {{0, 0}};
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.integration.dt = 1.0f / 60.0f;
    s.settings.integration.substeps = 20;
    MassSpring sim = build_simulation(s);
    Settler settler;
    int steps = 0;
    while (!settler.after_step(sim) && steps < 600) {
        sim.run_steps(1);
        ++steps;
    }
    REQUIRE(settler.settled());
    REQUIRE(settler.damping());
    CHECK(settler.damping_rate() == Approx(20.0).epsilon(0.01));
    // At the spring's stretch m g / k, within the residual's worth of it: r g / omega^2 (which, for one mode, is
    // what the residual stands for; 5% for the step's averaging and float positions).
    CHECK(sim.position(0).y - sim.position(1).y ==
          Approx(0.5 + 0.1 * 9.81 / 10.0).margin(1.05 * settler.residual().value * 9.81 / 100.0));
    // Stiffer, the damping follows: 4x the stiffness, twice the rate, up to options.damping_max.
    for (const float k : {40.0f, 1000.0f}) {
        Scene stiff = s;
        stiff.settings.springs.structural = glm::vec2(k);
        MassSpring again = build_simulation(stiff);
        Settler next;
        for (int i = 0; i < 600 && !next.after_step(again); ++i) again.run_steps(1);
        REQUIRE(next.settled());
        const double critical = 2.0 * std::sqrt(k / 0.1);
        INFO("k = " << k << " N/m: critical damping " << critical << "/s, the settle's " << next.damping_rate() << "/s");
        REQUIRE(next.damping());
        CHECK(next.damping_rate() == Approx(std::min(critical, next.options().damping_max)).epsilon(0.02));
    }
    // Within the integrator's own limits: symplectic Euler's damping is explicit (its bound on w h is
    // 2 sqrt(1 - c h / 2)), so at one substep of 1/60 s the settle adds at most c h = 0.1, 6/s, not 2 omega.
    Scene explicit_damping = s;
    explicit_damping.settings.integration.integrator = Integrator::SymplecticEuler;
    explicit_damping.settings.integration.substeps = 1;
    MassSpring symplectic = build_simulation(explicit_damping);
    Settler capped;
    for (int i = 0; i < 600 && !capped.after_step(symplectic); ++i) {
        REQUIRE(symplectic.settle_damping() <= 6.0 + 1e-9);
        symplectic.run_steps(1);
    }
    REQUIRE(capped.settled());
    REQUIRE(capped.damping());
    CHECK(capped.damping_rate() == Approx(6.0));
}
