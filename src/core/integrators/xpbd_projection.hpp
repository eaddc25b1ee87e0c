// One XPBD projection of one element (Macklin, Mueller & Chentanez 2016, with the multiplier starting at 0
// each substep: one iteration, "Small Steps"), the arithmetic every XPBD order shares: step_xpbd's list order
// (integrators.hpp) and ColouredXpbd's colours (coloured_xpbd.hpp). Each returns the element's C^2 at the
// positions it found, and leaves the multiplier in `lambda`.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include "model/forces.hpp"

#include <cmath>

namespace clothsim {

// A spring C = |x_b - x_a| - L0 with compliance alpha~ = 1 / (k h^2): d_lambda = -C / (w_a + w_b + alpha~), and
// x_a -= w_a lambda n, x_b += w_b lambda n with n = d / |d|, computed as lambda / |d| times d.
inline double project_spring(State& state, const Spring& s, double k, double h, double& lambda) {
    const double wa = state.inverse_mass[s.a], wb = state.inverse_mass[s.b];
    const glm::dvec3 d = state.position.get(s.b) - state.position.get(s.a);
    const double length = std::sqrt((d.x * d.x + d.y * d.y) + d.z * d.z);
    if (!(length > 1e-12)) return 0.0;
    const double c = length - static_cast<double>(s.rest_length);
    lambda = -c / ((wa + wb) + 1.0 / (k * h * h));
    const double g = lambda / length;
    state.position.add(s.a, d * -(wa * g));
    state.position.add(s.b, d * (wb * g));
    return c * c;
}

// A bend: the vector constraint C = x_a - 2 x_m + x_b with gradients I, -2 I, I:
// d_lambda = -C / (w_a + 4 w_m + w_b + 1 / (k h^2)).
inline double project_bend(State& state, const Bend& b, double k, double h, glm::dvec3& lambda) {
    const double wa = state.inverse_mass[b.a], wm = state.inverse_mass[b.m], wb = state.inverse_mass[b.b];
    const glm::dvec3 c = bend_difference(state.position, b);
    lambda = c * (-1.0 / (((wa + 4.0 * wm) + wb) + 1.0 / (k * h * h)));
    state.position.add(b.a, wa * lambda);
    state.position.add(b.m, (-2.0 * wm) * lambda);
    state.position.add(b.b, wb * lambda);
    return (c.x * c.x + c.y * c.y) + c.z * c.z;
}

// A hinge: the vector constraint C = sum_i c_i x_i with gradients c_i I: d_lambda = -C / (sum_i w_i c_i^2 + 1 / (k h^2)).
inline double project_hinge(State& state, const Hinge& hinge, double k, double h, glm::dvec3& lambda) {
    double w = 0.0;
    for (int i = 0; i < 4; ++i) w += double(state.inverse_mass[hinge.v[i]]) * double(hinge.c[i]) * double(hinge.c[i]);
    const glm::dvec3 c = hinge_difference(state.position, hinge);
    lambda = c * (-1.0 / (w + 1.0 / (k * h * h)));
    for (int i = 0; i < 4; ++i) {
        state.position.add(hinge.v[i], (double(state.inverse_mass[hinge.v[i]]) * double(hinge.c[i])) * lambda);
    }
    return (c.x * c.x + c.y * c.y) + c.z * c.z;
}

}  // namespace clothsim
