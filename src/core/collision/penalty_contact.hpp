// Penalty contact (colliders.contact = penalty): each enabled collider pushes each free particle at depth
// p > 0 (thickness minus its distance to the surface, the same depth the projection uses:
// shapes/shape.hpp) along the surface normal with
//
//   F = k_c p^3 / t^2,   potential U = k_c p^4 / (4 t^2),   stiffness dF/dp = 3 k_c p^2 / t^2,
//
// k_c = colliders.contact_stiffness and t = colliders.thickness (F = k_c p at p = t: k_c is the secant
// stiffness of the whole shell). Why this law, not the projection or a linear spring:
//  - Smooth at onset. F, dF/dp and d2F/dp2 all vanish at p = 0, so the force is C2 along the motion of a
//    particle entering the shell: its velocity has a continuous third time derivative there and a step that
//    straddles the onset loses RK4 no order (its local error stays O(h^4) at the finitely many onsets,
//    hence global O(h^4); Hairer, Norsett & Wanner, "Solving ODEs I", II.6 on discontinuities). A linear
//    penalty k p has a kink in F (order drops to 2), the projection an impulse (order 0 in position).
//    The geometry keeps that smoothness on a face, the sphere and the cylinder's side, and in the round shell
//    around a box edge or a cylinder rim, but not where those meet: there the depth's curvature jumps (0 on
//    the face's side, 1/distance on the rim's), so F is continuous with a jump in its derivative. A particle
//    that crosses such a plane while in the shell (it slides off a face over a rim) loses RK4's order there,
//    not conservation (measured at a cylinder rim: test_contact_penalty.cpp).
//  - A nonlinear power law, as in Hertz's contact (F ~ p^(3/2); Johnson, "Contact Mechanics", 1985, 4.2)
//    and in the Hunt & Crossley model (F = k p^n + lambda p^n p'; Hunt & Crossley 1975, J. Appl. Mech.
//    42(2)), with the exponent n = 3 chosen for smoothness rather than fitted to a material, and without
//    Hunt-Crossley's dissipative term, so the contact is conservative: MassSpring::energy() adds U and total
//    energy is conserved by an undamped run (a test checks it).
//  - Frictionless and with no continuous collision: a tangential force of Coulomb's kind switches between
//    stick and slip (non-smooth again), and a particle fast enough to cross the shell in one substep passes
//    through. Contact friction is the projection model's (colliders.hpp).
// Each particle's pushes are summed in double (the state's precision) and added once in the force type F:
// float for the simulation (the fast and textbook paths call this same function, so they stay
// bit-identical), double for the reference solution.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

namespace clothsim {

// Adds the contact force of every enabled collider to every free particle (N). Does nothing when the
// thickness is not positive (no shell: scene files reject that in penalty mode, settings.hpp).
template <class F>
void accumulate_contact_forces(const State& state, const ColliderSettings& colliders, BasicVec3Array<F>& force);

// J: sum over free particles and enabled colliders of k_c p^4 / (4 t^2).
double contact_potential_energy(const State& state, const ColliderSettings& colliders);

// N/m: the stiffness the stability bound (stability.cpp) gives a particle's contacts: 3 k_c, the value of
// dF/dp at p = t (the particle at the collider's surface), once per enabled collider (a particle may touch
// several at once). A contact deeper than the shell is stiffer; the bound holds while none is.
double contact_stiffness_bound(const ColliderSettings& colliders);

}  // namespace clothsim
