// Position Verlet with physical-unit damping.
//
// The model is x'' = a - c x' (a = F/m + g, c the damping rate in 1/s). Central differences,
//   (x' - 2x + x_prev) / h^2 = a - c (x' - x_prev) / (2h),
// give x' = [2x - (1 - c h/2) x_prev + a h^2] / (1 + c h/2), which is the per-step drag form (Jakobsen,
// "Advanced Character Physics", GDC 2001)
//   x' = x + (x - x_prev)(1 - d) + a h^2 / (1 + c h/2)   with   d = c h / (1 + c h/2).
// d is derived from c and h each step, so the damping a user sees does not change when h changes, and the
// scheme stays second order with damping on.
#pragma once

#include "clothsim/state.hpp"

#include <glm/vec3.hpp>

#include <vector>

namespace clothsim {

// The per-substep constants of the update x' - x = (x - x_prev) keep + a h2, shared by every solver. keep is
// double: at h = 1e-5 s and c = 0.2 1/s, d = 2e-6, which float would hold only to 1.5%. h2 scales the
// float velocity change a h2 (state.hpp), so a relative 6e-8 in it is the force's own precision.
struct VerletCoefficients {
    double keep;  // 1 - d, d = c h / (1 + c h/2)
    float h2;     // h^2 / (1 + c h/2)
};
inline VerletCoefficients verlet_coefficients(double damping, double h) {
    const double half_ch = 0.5 * damping * h;
    return {1.0 - damping * h / (1.0 + half_ch), static_cast<float>(h * h / (1.0 + half_ch))};
}

// One substep of length h for every free particle; pinned particles stay where they are. The substep's
// change (F/m + g) h2 is computed in float, the motion and the position in double.
void integrate_verlet(State& state, const Vec3Array& force, glm::vec3 gravity, double damping, double h);
// The same for particles [first, last) alone (each particle's update is its own: any split gives the same bits),
// leaving state.substep to the caller.
void integrate_verlet(State& state, const Vec3Array& force, glm::vec3 gravity, double damping, double h,
                      std::size_t first, std::size_t last);

// Second-order start: x - x_prev = v h - (a - c v) h^2 / 2, with a = F/m + g at x. Sets state.substep = h.
void start_verlet(State& state, const std::vector<glm::dvec3>& velocity, const Vec3Array& force,
                  glm::vec3 gravity, double damping, double h);

// Second-order velocity at the current positions, from the Taylor expansion of x_prev around x:
//   v (1 + c h/2) = (x - x_prev) / h + a h / 2.
// State keeps x - x_prev as `motion` (see state.hpp for why).
std::vector<glm::dvec3> verlet_velocities(const State& state, const Vec3Array& force, glm::vec3 gravity,
                                          double damping);

}  // namespace clothsim
