#include "clothsim/settle.hpp"

#include "clothsim/integrator.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clothsim {

Residual equilibrium_residual(const MassSpring& sim, std::vector<glm::dvec3>* moved) {
    // One step of a copy from rest, with the scene's integrator, contact, friction, tethers and strain limit.
    MassSpring probe(sim);
    probe.set_settle_damping(0.0);  // the scene's own dynamics
    probe.stop();
    probe.run_steps(1);
    const double dt = sim.settings().integration.dt;
    const double fall = 0.5 * glm::length(glm::dvec3(sim.settings().forces.gravity)) * dt * dt;
    Residual worst{0.0, 0};
    const State& before = sim.state();
    const State& after = probe.state();
    if (moved) moved->assign(before.size(), glm::dvec3(0.0));
    for (std::size_t i = 0; i < before.size(); ++i) {
        if (before.pinned[i]) continue;
        const glm::dvec3 move = after.position.get(i) - before.position.get(i);
        if (moved) (*moved)[i] = move;
        // A NaN counts as the worst (a cloth that blew up is not settled).
        const double length = glm::length(move);
        const double r = fall > 0.0 ? length / fall : length > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
        if (!(r <= worst.value)) worst = {std::isnan(r) ? std::numeric_limits<double>::infinity() : r, i};
    }
    return worst;
}

namespace {

// omega^2 of the motion between two checks, the Rayleigh quotient -sum m dx.da / sum m |dx|^2 (settle.hpp), with
// a = 2 move / dt^2 the residual's accelerations; NaN where it says nothing (no motion, or no restoring force).
double rayleigh_omega_squared(const State& state, const std::vector<glm::dvec3>& position,
                              const std::vector<glm::dvec3>& move, const std::vector<glm::dvec3>& checked_position,
                              const std::vector<glm::dvec3>& checked_move, double dt) {
    if (checked_position.size() != position.size() || dt <= 0.0) return std::nan("");
    double restoring = 0.0, inertia = 0.0;
    for (std::size_t i = 0; i < position.size(); ++i) {
        const float w = state.inverse_mass[i];
        if (state.pinned[i] || !(w > 0.0f)) continue;
        const double m = 1.0 / w;
        const glm::dvec3 dx = position[i] - checked_position[i];
        const glm::dvec3 da = (move[i] - checked_move[i]) * (2.0 / (dt * dt));
        restoring -= m * glm::dot(dx, da);
        inertia += m * glm::dot(dx, dx);
    }
    const double omega_squared = restoring / inertia;
    return inertia > 0.0 && omega_squared > 0.0 && std::isfinite(omega_squared) ? omega_squared : std::nan("");
}

}  // namespace

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
        std::vector<glm::dvec3> move;
        residual_ = equilibrium_residual(sim, &move);
        settled_ = residual_.value < options_.tolerance;
        next_check_ = sim.time() + options_.check_every;
        std::vector<glm::dvec3> position(sim.particle_count());
        for (std::size_t i = 0; i < position.size(); ++i) position[i] = sim.state().position.get(i);
        const double omega_squared = rayleigh_omega_squared(sim.state(), position, move, checked_position_,
                                                            checked_move_, sim.settings().integration.dt);
        if (options_.damping_max > 0.0 && std::isfinite(omega_squared) &&
            (damping() || residual_.value < options_.damping_below)) {
            if (!damping()) damping_since_ = sim.time();
            damping_rate_ = std::clamp(2.0 * std::sqrt(omega_squared), options_.damping_min, options_.damping_max);
        }
        checked_position_ = std::move(position);
        checked_move_ = std::move(move);
    }
    // Held on the cloth at every step (a cloth rebuilt mid-settle starts without it), and taken off once settled.
    // Kept clear of the damping's own stability limits (stability.cpp): where the integrator's damping is
    // explicit (symplectic Euler's bound w h < 2 sqrt(1 - c h / 2)), c h adds 0.1 at most, lowering that bound by
    // 2.5%; where the damping alone is stable while c h < a limit (RK4, XPBD), it takes half the room left.
    const IntegratorInfo& info = integrator_info(sim.settings().integration.integrator);
    const double h = sim.substep_length();
    if (info.explicit_damping) damping_rate_ = std::min(damping_rate_, 0.1 / h);
    if (info.damping_limit > 0.0) {
        const double room = info.damping_limit / h - sim.settings().springs.damping;
        damping_rate_ = std::min(damping_rate_, std::max(0.0, 0.5 * room));
    }
    sim.set_settle_damping(damping() && !settled_ ? damping_rate_ : 0.0);
    return settled_;
}

}  // namespace clothsim
