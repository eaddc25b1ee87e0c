// The velocity-based integrators. Position Verlet (verlet.hpp) and the fast solver keep
// motion = x - x_prev; these keep motion = v h (State::integrator says which), so switching between them is
// a restart from the current velocities. All of them get forces from the same function (springs and wind,
// MassSpring::compute_forces) and leave collisions to the same stage after them.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include <functional>

namespace clothsim {

// Forces (N) at a state: reads positions and, for wind, motion / substep as the velocity. F is the force
// type: float for the simulation, double for the reference solution. The state is double either way.
template <class F>
using BasicForceFunction = std::function<void(const State&, BasicVec3Array<F>&)>;
using ForceFunction = BasicForceFunction<float>;

// What every integrator needs besides the state.
template <class F>
struct BasicDynamics {
    const BasicForceFunction<F>& forces;    // springs and wind
    const BasicForceFunction<F>& external;  // wind only (XPBD treats springs as constraints)
    glm::vec3 gravity;                      // m/s^2
    float damping;                          // 1/s: a = F/m + g - c v
};
using Dynamics = BasicDynamics<float>;

// a = F/m + g - c v (in double) for free particles, 0 for pinned ones; v = motion / h.
template <class F>
void accelerations(const State& state, const BasicVec3Array<F>& force, glm::vec3 gravity, double damping,
                   DVec3Array& out);

// Semi-implicit Euler: v' = v + h a(x, v), x' = x + h v'. First order; symplectic without damping.
void step_symplectic_euler(State& state, const Dynamics& dynamics, double h);

// Classical Runge-Kutta on (x, v): four force evaluations, fourth order. Float forces for the simulation,
// double forces for the reference solution.
template <class F>
void step_rk4(State& state, const BasicDynamics<F>& dynamics, double h);

// Backward Euler linearised once (Baraff & Witkin 1998):
//   ((1 + h c) M - h^2 K) dv = h (F + M g - c M v + h K v),   v' = v + dv,   x' = x + h v'
// with K the spring Jacobian, its transverse part clamped for compressed springs so the matrix stays
// symmetric positive definite, solved by conjugate gradients to `tolerance` (relative residual). Pinned
// particles are held by filtering their rows out of the solve. Returns the CG iterations used and the
// relative residual |b - A dv| / |b| it stopped at (0 when b = 0).
// The linear solve is in float (it finds the velocity change); the state update adds it in double.
struct LinearSolve {
    int iterations = 0;
    double residual = 0.0;
};
LinearSolve step_implicit_euler(State& state, const Dynamics& dynamics, const Topology& topology,
                        const SpringSettings& springs, float tolerance, double h);

// XPBD (Macklin et al. 2016) with one constraint iteration per substep ("Small Steps", Macklin et al.
// 2019): predict with external accelerations (gravity, wind, damping), then project every spring
// C = |x_b - x_a| - L0 once, in list order, with compliance 1/k; v = (x' - x) / h. Converges to the
// spring model as the substep shrinks. The projection is computed in double: its corrections are as small
// as the substep's motion.
// It records each constraint's multiplier, so that the constraint residual |C(x) + alpha~ lambda|
// (Macklin, Mueller & Chentanez 2016, eq. 9: zero when the projection has converged; alpha~ = 1/(k h^2)) can
// be measured at the end of the step, after collisions too, relative to |C| of the prediction.
struct XpbdMultipliers {
    std::vector<double> spring;     // per spring
    std::vector<glm::dvec3> bend;   // per bend (a vector constraint)
    std::vector<glm::dvec3> hinge;  // per hinge (a vector constraint)
    std::vector<glm::dvec3> membrane;  // per membrane triangle: (e_u, e_v, gamma)'s
    double substep = 0.0;           // s
    double initial_violation = 0.0; // |C| at the prediction, over all springs and bends
};
void step_xpbd(State& state, const Dynamics& dynamics, const Topology& topology, const SpringSettings& springs,
               double h, XpbdMultipliers& multipliers);
// |C(x) + alpha~ lambda| / |C(prediction)| at `position` for the multipliers of the last substep (0 before one).
double xpbd_residual(const DVec3Array& position, const Topology& topology, const SpringSettings& springs,
                     const XpbdMultipliers& multipliers);

}  // namespace clothsim
