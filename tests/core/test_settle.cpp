// Settling to rest (settle.hpp): the residual measures what it says, and kinetic damping reaches an equilibrium
// of the model that the dynamics then keep, sooner than the dynamics reach it.
#include "clothsim/scene.hpp"
#include "clothsim/settle.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>

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
    // Near an equilibrium: a further 2 s of the plain dynamics from there move no particle by more than 3 mm.
    // A residual r is a force r m g the cloth's softest mode (its sway, about 0.5 Hz) answers with a displacement
    // of r g / omega^2, 2 mm at r = 0.01: a force residual bounds the distance to equilibrium only through the
    // stiffness (measured: 1.8 mm at r = 0.0074, 0.84 mm at r = 0.0028).
    MassSpring kept = settling;
    kept.run_steps(120);
    INFO("the dynamics then move it by " << test::largest_distance(kept, settling) << " m");
    CHECK(test::largest_distance(kept, settling) < 3e-3);
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
