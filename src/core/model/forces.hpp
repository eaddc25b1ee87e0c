// Force stages of a time step. Each adds its contribution (N) to `force`; none clears it.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

namespace clothsim {

// Hooke springs, F_a = k w (|d| - L0) d/|d| with d = x_b - x_a, and -F_a on b (a structural spring with a
// stretch curve: k w t(|d| - L0) d/|d|, t its SpringCurve::stretch_term); then the bends
// (spring.hpp): with d = x_a - 2 x_m + x_b, F_a = F_b = -k w d and F_m = 2 k w d; then the hinges: with
// d = sum_i c_i x_i, F_i = -k c_i d; then a mesh cloth's membrane triangles (membrane.hpp): bu_i p_u, then
// bv_i p_v, on each corner i; then a flat mesh cloth's Gaussian-curvature term (gaussian_curvature.hpp). A spring with L0 = 0 uses
// F_a = k d (the same formula without the division); one with L0 > 0 whose ends coincide has no direction
// and contributes nothing rather than NaN.
// d is taken in double and rounded once to the force type F; the rest is computed in F. Instantiated for
// float (the simulation; the fast solver rounds operation for operation alike) and double (the reference).
template <class F>
void accumulate_spring_forces(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                              BasicVec3Array<F>& force);

// Soft clips' holds (state.hpp): F = -k (x - anchor) on each held particle, computed in double and added in
// the force type F.
template <class F>
void accumulate_soft_clip_forces(const Topology& topology, const DVec3Array& position, BasicVec3Array<F>& force);

// Air velocity at a time: the wind vector scaled by deterministic gusts (two incommensurate sines, so a
// run is reproducible and still looks irregular).
glm::vec3 wind_velocity(const ForceSettings& forces, double time);

// Aerodynamic pressure. Triangles model: each triangle of area A and unit normal n, moving with the mean
// velocity v of its corners, feels F = drag * A * (w_rel . n) |w_rel . n| n with w_rel = w - v, shared
// equally by its corners; a sheet edge-on to the wind feels nothing. Uniform model: every particle feels
// drag * (A_total / N) * |w_rel| w_rel. Velocities are the first-order (x - x_prev) / h. Computed in double,
// added in the force type F (float for the simulation, double for the reference).
template <class F>
void accumulate_wind_forces(const Topology& topology, const State& state, const ForceSettings& forces,
                            double rest_area, BasicVec3Array<F>& force);

// Elastic energy 0.5 k w (|d| - L0)^2 summed over springs, plus 0.5 k w |x_a - 2 x_m + x_b|^2 over bends,
// 0.5 k |sum_i c_i x_i|^2 over hinges, the membrane triangles' energy (membrane.hpp), the Gaussian-curvature
// term's (gaussian_curvature.hpp) and
// 0.5 k |x - anchor|^2 over soft clips' holds (J).
double spring_potential_energy(const Topology& topology, const DVec3Array& position,
                               const SpringSettings& springs);

// Stiffness of a spring or bend of a kind along an axis (N/m), before its weight.
inline float stiffness_of(const SpringSettings& springs, SpringKind kind, Axis axis) {
    switch (kind) {
        case SpringKind::Structural: return axis == Axis::V ? springs.structural.y : springs.structural.x;
        case SpringKind::Shear: return springs.shear;
        case SpringKind::Bending: return axis == Axis::V ? springs.bending.y : springs.bending.x;
    }
    return 0.0f;
}
// A spring's k w and a bend's k w: products with a power-of-two weight, exact in float.
inline float stiffness_of(const SpringSettings& springs, const Spring& s) {
    return stiffness_of(springs, s.kind, s.axis) * s.weight;
}
// A spring's stretch curve (stretch_curve.hpp): its axis's for a grid's structural spring, its warp level's blend
// for a mesh cloth's material spring, none (linear) otherwise.
inline const SpringCurve& curve_of(const SpringSettings& springs, SpringKind kind, Axis axis) {
    static const SpringCurve kLinear{};
    if (kind != SpringKind::Structural || axis == Axis::Diagonal) return kLinear;
    return springs.stretch_curve[axis == Axis::V ? 1 : 0];
}
inline const SpringCurve& curve_of(const SpringSettings& springs, const Spring& s) {
    if (s.warp_level != 0) return springs.mesh_curve[s.warp_level - 1];  // a mesh cloth's material spring
    return curve_of(springs, s.kind, s.axis);
}
// Whether a mesh cloth's springs have curves (the fast mesh paths then take their scalar order).
inline bool has_mesh_curves(const SpringSettings& springs) {
    return std::any_of(springs.mesh_curve.begin(), springs.mesh_curve.end(), [](const SpringCurve& c) { return c.knots > 0; });
}
// Whether any spring has a curve, a grid's or a mesh cloth's.
inline bool has_curves(const SpringSettings& springs) {
    return springs.stretch_curve[0].knots > 0 || springs.stretch_curve[1].knots > 0 || has_mesh_curves(springs);
}
// A spring's elastic energy (J) at `stretch` = |d| - L0, for its k w: 0.5 k w stretch^2, or with a stretch curve
// k w times the curve's energy_term.
inline double spring_energy(double k, const SpringCurve& curve, double stretch, double rest) {
    return curve.knots == 0 ? 0.5 * k * stretch * stretch : k * curve.energy_term(stretch, rest);
}
inline float stiffness_of(const SpringSettings& springs, const Bend& b) {
    return stiffness_of(springs, SpringKind::Bending, b.axis) * b.weight;
}
// A hinge's k, kept at 0 or more: a calibrated hinge's share can be negative (cloth_mesh.cpp, calibrate_hinges).
inline float stiffness_of(const SpringSettings& springs, const Hinge& h) {
    return std::max(0.0f, springs.bending.x * h.weight_u + springs.bending.y * h.weight_v);
}
// A hinge's sum_i c_i x_i (spring.hpp), in double, for particles v and weights c.
inline glm::dvec3 hinge_difference(const DVec3Array& position, const std::array<std::size_t, 4>& v,
                                   const std::array<double, 4>& c) {
    // Relative to v[0], so the sum keeps the precision of the small differences (the weights sum to 0).
    const glm::dvec3 o = position.get(v[0]);
    return c[1] * (position.get(v[1]) - o) + c[2] * (position.get(v[2]) - o) + c[3] * (position.get(v[3]) - o);
}
inline glm::dvec3 hinge_difference(const DVec3Array& position, const Hinge& h) {
    return hinge_difference(position, {h.v[0], h.v[1], h.v[2], h.v[3]},
                            {double(h.c[0]), double(h.c[1]), double(h.c[2]), double(h.c[3])});
}
// The second difference x_a - 2 x_m + x_b of a bend, in double: (x_a - x_m) + (x_b - x_m).
inline glm::dvec3 bend_difference(const DVec3Array& position, const Bend& b) {
    const glm::dvec3 m = position.get(b.m);
    return (position.get(b.a) - m) + (position.get(b.b) - m);
}

}  // namespace clothsim
