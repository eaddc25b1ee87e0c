// The velocity-based integrators. Position Verlet (verlet.hpp) and its fast grid solver keep
// motion = x - x_prev; these keep motion = v h (State::integrator says which), so switching between them is
// a restart from the current velocities. All of them get forces from the same function (springs and wind,
// MassSpring::compute_forces) and leave collisions to the same stage after them.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include <functional>

namespace clothsim {

// Forces (N) at a state: reads positions and, for wind, motion / substep as the velocity.
using ForceFunction = std::function<void(const State&, Vec3Array&)>;

// What every integrator needs besides the state.
struct Dynamics {
    const ForceFunction& forces;    // springs and wind
    const ForceFunction& external;  // wind only (XPBD treats springs as constraints)
    glm::vec3 gravity;              // m/s^2
    float damping;                  // 1/s: a = F/m + g - c v
};

// a = F/m + g - c v for free particles, 0 for pinned ones; v = motion / h.
void accelerations(const State& state, const Vec3Array& force, glm::vec3 gravity, float damping,
                   Vec3Array& out);

// Semi-implicit Euler: v' = v + h a(x, v), x' = x + h v'. First order; symplectic without damping.
void step_symplectic_euler(State& state, const Dynamics& dynamics, float h);

// Classical Runge-Kutta on (x, v): four force evaluations, fourth order.
void step_rk4(State& state, const Dynamics& dynamics, float h);

// Backward Euler linearised once (Baraff & Witkin 1998):
//   ((1 + h c) M - h^2 K) dv = h (F + M g - c M v + h K v),   v' = v + dv,   x' = x + h v'
// with K the spring Jacobian, its transverse part clamped for compressed springs so the matrix stays
// symmetric positive definite, solved by conjugate gradients to `tolerance` (relative residual). Pinned
// particles are held by filtering their rows out of the solve. Returns the CG iterations used.
int step_implicit_euler(State& state, const Dynamics& dynamics, const Topology& topology,
                        const SpringSettings& springs, float tolerance, float h);

// XPBD (Macklin et al. 2016) with one constraint iteration per substep ("Small Steps", Macklin et al.
// 2019): predict with external accelerations (gravity, wind, damping), then project every spring
// C = |x_b - x_a| - L0 once, in list order, with compliance 1/k; v = (x' - x) / h. Converges to the
// spring model as the substep shrinks.
void step_xpbd(State& state, const Dynamics& dynamics, const Topology& topology, const SpringSettings& springs,
               float h);

}  // namespace clothsim
