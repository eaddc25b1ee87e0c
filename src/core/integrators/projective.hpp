// Projective dynamics for the mass-spring cloth: an integrator for stiff cloth at large steps.
//
// Each substep is one step of BDF2 (second order, A-stable), written as the minimisation of
//   g(x) = 1/(2 h'^2) (x - y)^T M' (x - y) + E(x),   h' = 2h/3,   M' = (1 + h' c) M
// over the free particles' positions x, with E the springs' and bends' energy and y the inertial target
// (projective.cpp derives it). Its minimiser is BDF2's x_{n+1}; v_{n+1} = (x_{n+1} - (4 x_n - x_{n-1})/3)/h'.
// g is minimised by L-BFGS (Liu, Bouaziz & Kavan 2017, "Quasi-Newton methods for real-time simulation of
// hyperelastic materials") whose initial Hessian is projective dynamics' global matrix (Liu, Bargteil,
// O'Brien & Kavan 2013, "Fast simulation of mass-spring systems"; Bouaziz et al. 2014):
//   A = M'/h'^2 + L,  L the springs' and bends' stiffness Laplacian, the same for x, y and z,
// so the first iteration is exactly a local-global step. A does not change while the settings, the substep
// and the pins stay: it is factorised once (sparse Cholesky, Eigen's SimplicialLDLT with an AMD ordering)
// and each iteration is one pair of triangular solves for x, y and z together. A backtracking line search
// makes every iteration lower g, so the step is stable at any stiffness and substep; more iterations converge
// to BDF2 itself. Bends, rest-length-0 springs and soft clips' holds are quadratic: A holds them exactly.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"
#include "integrators/integrators.hpp"

#include <memory>

namespace clothsim {

class ProjectiveSolver {
public:
    // What each step needs besides the state: the forces held fixed over the substep (wind, contact, a grab,
    // evaluated at its start; not soft clips' holds, which the step takes implicitly from the topology),
    // gravity and the damping rate c (1/s, a = F/m + g - c v).
    struct Inputs {
        const Vec3Array* external = nullptr;  // N, or null for none
        glm::vec3 gravity{0.0f};
        float damping = 0.0f;
        int iterations = 10;     // the most local-global iterations per substep
        float tolerance = 0.0f;  // stop once the relative residual (below) falls under this
    };

    // The factorisation depends on the springs' stiffness, the masses, the pins, the substep and the damping:
    // whoever changes one of them calls this (MassSpring::apply, set_pinned); the next step factorises anew.
    void invalidate_matrix() { factor_.reset(); }

    // Advances `state` (motion = v h) by the substep h. `continues` says that the state is the one the
    // previous call left (a collision or a limit may have corrected it), so BDF2 may use that call's start
    // as x_{n-1}; otherwise the history is made from the state's own acceleration (second-order start).
    // Returns the iterations used and the relative residual at the end: |grad g(x)| over the larger of its value
    // where the iterations start and |M' (g + f_ext / m)| (the loads, so a cloth at rest has a scale too).
    LinearSolve step(State& state, const Topology& topology, const SpringSettings& springs, const Inputs& inputs,
                     double h, bool continues);

    struct Factor;  // the factorised matrix; Eigen's types stay in projective.cpp

private:
    std::shared_ptr<const Factor> factor_;  // immutable once made: copies of a simulation share it
    DVec3Array previous_position_;          // x_{n-1} and v_{n-1}: the start of the previous step
    DVec3Array previous_velocity_;
};

}  // namespace clothsim
