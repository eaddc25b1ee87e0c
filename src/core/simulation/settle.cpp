#include "clothsim/settle.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clothsim {

Residual equilibrium_residual(const MassSpring& sim) {
    // One step of a copy from rest, with the scene's integrator, contact, friction, tethers and strain limit.
    MassSpring probe(sim);
    probe.stop();
    probe.run_steps(1);
    const double dt = sim.settings().integration.dt;
    const double fall = 0.5 * glm::length(glm::dvec3(sim.settings().forces.gravity)) * dt * dt;
    Residual worst{0.0, 0};
    const State& before = sim.state();
    const State& after = probe.state();
    for (std::size_t i = 0; i < before.size(); ++i) {
        if (before.pinned[i]) continue;
        const double moved = glm::length(after.position.get(i) - before.position.get(i));
        // A NaN counts as the worst (a cloth that blew up is not settled).
        const double r = fall > 0.0 ? moved / fall : moved > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
        if (!(r <= worst.value)) worst = {std::isnan(r) ? std::numeric_limits<double>::infinity() : r, i};
    }
    return worst;
}

bool Settler::after_step(MassSpring& sim) {
    // A sleeping cloth is held where it stopped, settled or not: wake it (from rest) until it is.
    if (sim.asleep() && !settled_) sim.wake();
    const double kinetic = sim.energy().kinetic;
    if (kinetic < kResetFraction * peak_kinetic_) {  // the swing is past its peak: stop it there
        sim.stop();
        ++resets_;
        peak_kinetic_ = 0.0;
    } else {
        peak_kinetic_ = std::max(peak_kinetic_, kinetic);
    }
    if (next_check_ < 0.0 || sim.time() >= next_check_) {
        residual_ = equilibrium_residual(sim);
        settled_ = residual_.value < options_.tolerance;
        next_check_ = sim.time() + options_.check_every;
    }
    return settled_;
}

}  // namespace clothsim
