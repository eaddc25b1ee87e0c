// Settling a cloth to rest, the state the Cusick test and every "how does it hang" question ask for, sooner than
// letting the dynamics ring down: dynamic relaxation with kinetic damping (Day 1965, "An introduction to dynamic
// relaxation", The Engineer 219; Barnes 1999, "Form finding and analysis of tension structures by dynamic
// relaxation", Int. J. Space Structures 14(2):89-104). The scene's own dynamics run, and every velocity is set
// to zero once the cloth's kinetic energy, read after each step, has fallen to half its peak since the last
// reset: the swing has passed its peak, near a minimum of the potential energy along its path, and would only
// swing on past it. Each reset takes out the energy a swing would carry, where the scene's damping takes it out
// over seconds. Barnes resets at the peak itself; read once a step, the stiff membrane's fast vibrations make
// the energy fall from one step to the next at random, and resetting on every fall then freezes the slow
// settling too (the bundled `cusick`: residual 0.04 after 2.4 s, against under 0.01 after 2.2 s at half the
// peak; resetting at a tenth lets swings through: 0.02-0.25 at 2-3.6 s). The state reached is an equilibrium of
// the same model (forces, contact, friction), one of the many a draped cloth has (which fold pattern depends on
// the path, as in the dynamics: docs/MATERIAL.md).
//
// Kinetic damping leaves the tail to the scene's damping: the small swings of folds and contacts after the fall,
// whose energy never falls to half its peak (the bundled `cusick` at 81 a side sat at residual 0.015-0.035 from
// 2 to 3.4 s at its 2/s). So once the fall is over (the residual under options.damping_below: no particle's net
// force above 30% of its weight) a viscous damping of the settle's own is added to the scene's
// (MassSpring::set_settle_damping): dynamic relaxation's original form (Otter 1966, "Computations for
// prestressed concrete reactor pressure vessels using dynamic relaxation", Nuclear Structural Engineering
// 1:61-75), at the critical c = 2 omega of the slowest mode, the fastest approach (Underwood 1983, "Dynamic
// relaxation", in Computational Methods for Transient Analysis). Omega is estimated at each check from the
// motion since the last one, as Papadrakakis (1981, "A method for the automatic evaluation of the dynamic
// relaxation parameters", CMAME 25:35-48) estimates it from successive iterates: near an equilibrium the net
// acceleration answers a displacement through M^-1 K, so the Rayleigh quotient of the change in position dx and
// in acceleration da, omega^2 = -sum m dx.da / sum m |dx|^2, weighs the modes the cloth is still moving in, and
// the slowest one dominates once the faster have been damped. The accelerations are the residual's own (its
// step from rest moves a particle a dt^2 / 2). A damping force vanishes at rest: the equilibria are the
// model's, and the residual is measured with the scene's damping alone.
#pragma once

#include "clothsim/mass_spring.hpp"

#include <glm/vec3.hpp>

#include <cstddef>
#include <limits>
#include <vector>

namespace clothsim {

// How far a state is from equilibrium: the largest net force on a free particle relative to its weight
// m |g|, springs, bends, gravity, wind, contact and friction together, averaged over one step. Measured by one
// step (integration.dt, the scene's substeps and integrator) of a copy started from rest, which moves a particle
// by about a dt^2 / 2 (a its mean acceleration) after contact has pushed it back out of a collider and friction
// has held it: residual = |x(dt) - x(0)| / (|g| dt^2 / 2). So a particle resting on a support counts as
// balanced, and a free-falling one has residual 1. Over a step the stiff membrane's own vibrations (periods
// under a millisecond, nanometres across) average out: read over one substep instead, they give a cloth at
// rest to the eye a residual of 3 to 10, the force of a nanometre's stretch at 4000 N/m against a 0.08 mN
// weight. Pinned particles are left out. `particle` is where the largest is (0 when none is free). `moved`, when
// not null, receives each particle's move over that step (zero for a pinned one).
struct Residual {
    double value = 0.0;
    std::size_t particle = 0;
};
Residual equilibrium_residual(const MassSpring& sim, std::vector<glm::dvec3>* moved = nullptr);

struct SettleOptions {
    double tolerance = 0.01;    // settled once the residual is below this (1% of a particle's weight)
    double check_every = 0.1;   // s of simulated time between residual checks (each costs one step)
    // The settle's viscous damping once the fall is over: 2 omega of the slowest mode, kept within
    // [damping_min, damping_max] 1/s (damping_max = 0: kinetic damping alone).
    double damping_below = 0.3;  // the residual at which the fall counts as over
    double damping_min = 1.0;
    double damping_max = 50.0;
};

// Drives the kinetic damping: call after_step after each step of the dynamics (through whatever runs the
// steps: a Stepper, the app's frame loop).
class Settler {
public:
    explicit Settler(SettleOptions options = {}) : options_(options) {}
    // Resets the velocities when the kinetic energy has fallen to half its peak, and every check_every of
    // simulated time measures the residual. Wakes a cloth that fell asleep before it settled. Returns settled().
    bool after_step(MassSpring& sim);
    bool settled() const { return settled_; }
    // The last residual measured (infinite before the first check).
    const Residual& residual() const { return residual_; }
    int resets() const { return resets_; }
    // Whether the settle's damping is on (the residual has fallen below options.damping_below, with an estimate
    // of the slowest mode), from which simulated time (negative while it is off), and its rate (1/s, within the
    // integrator's own limits on damping; 0 while off).
    bool damping() const { return damping_since_ >= 0.0; }
    double damping_since() const { return damping_since_; }
    double damping_rate() const { return damping_rate_; }
    const SettleOptions& options() const { return options_; }

private:
    static constexpr double kResetFraction = 0.5;
    SettleOptions options_;
    double peak_kinetic_ = 0.0;
    double next_check_ = -1.0;  // simulated time of the next residual check; < 0: at the first step
    Residual residual_{std::numeric_limits<double>::infinity(), 0};
    int resets_ = 0;
    double damping_since_ = -1.0;
    double damping_rate_ = 0.0;
    // At the last check: the positions and the residual's moves, for the next check's estimate of omega.
    std::vector<glm::dvec3> checked_position_, checked_move_;
    bool settled_ = false;
};

}  // namespace clothsim
