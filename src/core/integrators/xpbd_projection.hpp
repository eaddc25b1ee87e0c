// One XPBD projection of one element (Macklin, Mueller & Chentanez 2016, with the multiplier starting at 0
// each substep: one iteration, "Small Steps"), the arithmetic every XPBD order shares: step_xpbd's list order
// (integrators.hpp) and ColouredXpbd's colours (coloured_xpbd.hpp). Each returns the element's C^2 at the
// positions it found, and leaves the multiplier in `lambda`.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include "model/forces.hpp"
#include "model/membrane.hpp"

#include <glm/mat3x3.hpp>

#include <array>
#include <cmath>
#include <cstddef>

namespace clothsim {

// A spring from particle a to b, C = |x_b - x_a| - L0, with compliance alpha~ = 1 / (k h^2):
// d_lambda = -C / (w_a + w_b + alpha~), and x_a -= w_a lambda n, x_b += w_b lambda n with n = d / |d|, computed as
// lambda / |d| times d. Leaves `lambda` alone where the spring has no length to project along.
// A structural spring with a stretch curve (stretch_curve.hpp) takes the compliance of its secant stiffness at
// the C it is projected from, k t(C) / C: alpha C / t(C). At the fixed point C + alpha~ lambda = 0 its force
// -lambda / h^2 is then k t(C), the curve's; a linear or compressed spring keeps alpha (t(C) = C).
inline double curved_compliance(double alpha, const SpringCurve& curve, double c, double rest_length) {
    if (curve.knots == 0 || !(c > 0.0)) return alpha;
    return alpha * (c / curve.stretch_term(c, rest_length));
}

// A spring's residual C + alpha~ lambda (Macklin, Mueller & Chentanez 2016, eq. 9) with alpha~ = 1 / (k h^2),
// a curved spring's at its secant compliance.
inline double spring_residual(double c, double lambda, double k, double h2, const SpringCurve& curve,
                              double rest_length) {
    return curve.knots == 0 ? c + lambda / (k * h2)
                            : c + lambda * curved_compliance(1.0 / (k * h2), curve, c, rest_length);
}

inline double project_spring(State& state, std::size_t a, std::size_t b, double rest_length, double alpha,
                             double& lambda, const SpringCurve* curve = nullptr) {
    const double wa = state.inverse_mass[a], wb = state.inverse_mass[b];
    const glm::dvec3 d = state.position.get(b) - state.position.get(a);
    const double length = std::sqrt((d.x * d.x + d.y * d.y) + d.z * d.z);
    if (!(length > 1e-12)) return 0.0;
    const double c = length - rest_length;
    if (curve) alpha = curved_compliance(alpha, *curve, c, rest_length);
    lambda = -c / ((wa + wb) + alpha);
    const double g = lambda / length;
    state.position.add(a, d * -(wa * g));
    state.position.add(b, d * (wb * g));
    return c * c;
}
inline double project_spring(State& state, const Spring& s, double k, double h, double& lambda,
                             const SpringCurve& curve) {
    return project_spring(state, s.a, s.b, static_cast<double>(s.rest_length), 1.0 / (k * h * h), lambda,
                          curve.knots ? &curve : nullptr);
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

// A hinge on particles v with weights c: the vector constraint C = sum_i c_i x_i with gradients c_i I:
// d_lambda = -C / (sum_i w_i c_i^2 + alpha~).
inline double project_hinge(State& state, const std::array<std::size_t, 4>& v, const std::array<double, 4>& c,
                            double alpha, glm::dvec3& lambda) {
    double w = 0.0;
    for (int i = 0; i < 4; ++i) w += double(state.inverse_mass[v[i]]) * c[i] * c[i];
    const glm::dvec3 C = hinge_difference(state.position, v, c);
    lambda = C * (-1.0 / (w + alpha));
    for (int i = 0; i < 4; ++i) state.position.add(v[i], (double(state.inverse_mass[v[i]]) * c[i]) * lambda);
    return (C.x * C.x + C.y * C.y) + C.z * C.z;
}
inline double project_hinge(State& state, const Hinge& hinge, double k, double h, glm::dvec3& lambda) {
    return project_hinge(state, {hinge.v[0], hinge.v[1], hinge.v[2], hinge.v[3]},
                         {double(hinge.c[0]), double(hinge.c[1]), double(hinge.c[2]), double(hinge.c[3])},
                         1.0 / (k * h * h), lambda);
}

// A membrane triangle (membrane.hpp) as one block of three constraints C = (e_u, e_v, gamma), whose energy
// 0.5 C^T K C with K = A [[C11, C12, 0], [C12, C22, 0], [0, 0, C66]] is the membrane's (Macklin, Mueller &
// Chentanez 2016 treat a block of constraints with a compliance matrix alpha = K^-1 alike): one Newton step of
// (J W J^T + alpha~) d_lambda = -C, alpha~ = K^-1 / h^2, with the gradients of membrane_forces. A curved
// direction takes its secant C11 t(e) / e (as curved_compliance), so the fixed point's stress is the curve's.
// Returns |C|^2 and leaves the multipliers in `lambda`; a collapsed triangle or a zero stretch is left alone.
inline bool membrane_compliance(const MembraneTensor& c, const SpringSettings& springs, const MembraneStrain& s,
                                  double area, double h2, glm::dmat3& alpha) {
    auto secant = [](const SpringCurve& curve, double e) {
        return curve.knots == 0 || !(e > 0.0) ? 1.0 : curve.stretch_term(e, 1.0) / e;
    };
    const double k11 = area * c.c11 * secant(springs.membrane_curve[0], s.eu);
    const double k22 = area * c.c22 * secant(springs.membrane_curve[1], s.ev);
    const double k12 = area * c.c12, det = k11 * k22 - k12 * k12;
    if (!(k11 > 0.0) || !(k22 > 0.0) || !(det > 0.0)) return false;
    alpha = glm::dmat3(0.0);
    alpha[0][0] = k22 / (det * h2);
    alpha[1][1] = k11 / (det * h2);
    alpha[0][1] = alpha[1][0] = -k12 / (det * h2);
    alpha[2][2] = c.c66 > 0.0 ? 1.0 / (area * c.c66 * h2) : 0.0;  // 0 marks a shear that is not projected
    return true;
}

// The block's matrix J W J^T + alpha~ in sums over the corners: with S_uu = sum_i w_i bu_i^2, S_vv, S_uv likewise,
// n = w / |w|, its entries are alpha~ plus S_uu n_u.n_u, S_vv n_v.n_v, S_uv n_u.n_v, S_uu n_u.w_v + S_uv n_u.w_u,
// S_uv n_v.w_v + S_vv n_v.w_u and S_uu w_v.w_v + 2 S_uv w_u.w_v + S_vv w_u.w_u; it is solved by its adjugate,
// and corner i moves by (w_i bu_i) P + (w_i bv_i) Q, P = l_0 n_u + l_2 w_v, Q = l_1 n_v + l_2 w_u. ColouredXpbd's
// AVX-512 pass does these operations in this order (the same bits).
inline double project_membrane(State& state, const Membrane& m, const MembraneTensor& c, const SpringSettings& springs,
                               double h, glm::dvec3& lambda) {
    lambda = glm::dvec3(0.0);
    const MembraneStrain s = membrane_strain(state.position, m, c, springs);
    if (!s.valid) return 0.0;
    glm::dmat3 alpha;
    if (!membrane_compliance(c, springs, s, double(m.area), h * h, alpha)) return 0.0;
    const bool shear = alpha[2][2] > 0.0;
    const glm::dvec3 nu = s.wu / s.lu, nv = s.wv / s.lv;
    double w[3], bu[3], bv[3];
    for (int i = 0; i < 3; ++i) w[i] = double(state.inverse_mass[m.v[i]]), bu[i] = double(m.bu[i]), bv[i] = double(m.bv[i]);
    const double suu = ((w[0] * bu[0]) * bu[0] + (w[1] * bu[1]) * bu[1]) + (w[2] * bu[2]) * bu[2];
    const double svv = ((w[0] * bv[0]) * bv[0] + (w[1] * bv[1]) * bv[1]) + (w[2] * bv[2]) * bv[2];
    const double suv = ((w[0] * bu[0]) * bv[0] + (w[1] * bu[1]) * bv[1]) + (w[2] * bu[2]) * bv[2];
    const double a00 = alpha[0][0] + suu * glm::dot(nu, nu);
    const double a11 = alpha[1][1] + svv * glm::dot(nv, nv);
    const double a01 = alpha[0][1] + suv * glm::dot(nu, nv);
    const double a02 = shear ? suu * glm::dot(nu, s.wv) + suv * glm::dot(nu, s.wu) : 0.0;
    const double a12 = shear ? suv * glm::dot(nv, s.wv) + svv * glm::dot(nv, s.wu) : 0.0;
    const double a22 = shear ? (alpha[2][2] + (suu * glm::dot(s.wv, s.wv) + 2.0 * suv * s.gamma)) + svv * glm::dot(s.wu, s.wu) : 1.0;
    const double c0 = s.eu, c1 = s.ev, c2 = shear ? s.gamma : 0.0;
    // The adjugate's rows (symmetric) and the determinant by the first row.
    const double m00 = a11 * a22 - a12 * a12, m01 = a02 * a12 - a01 * a22, m02 = a01 * a12 - a02 * a11;
    const double m11 = a00 * a22 - a02 * a02, m12 = a01 * a02 - a00 * a12, m22 = a00 * a11 - a01 * a01;
    const double det = (a00 * m00 + a01 * m01) + a02 * m02;
    const double l0 = -((m00 * c0 + m01 * c1) + m02 * c2) / det;
    const double l1 = -((m01 * c0 + m11 * c1) + m12 * c2) / det;
    const double l2 = -((m02 * c0 + m12 * c1) + m22 * c2) / det;
    lambda = glm::dvec3(l0, l1, l2);
    const glm::dvec3 P = l0 * nu + l2 * s.wv, Q = l1 * nv + l2 * s.wu;
    for (int i = 0; i < 3; ++i) state.position.add(m.v[i], (w[i] * bu[i]) * P + (w[i] * bv[i]) * Q);
    return (c0 * c0 + c1 * c1) + c2 * c2;
}

// A membrane's residual C + alpha~ lambda at `position` (3 components).
inline glm::dvec3 membrane_residual(const DVec3Array& position, const Membrane& m, const MembraneTensor& c,
                                    const SpringSettings& springs, double h2, const glm::dvec3& lambda) {
    const MembraneStrain s = membrane_strain(position, m, c, springs);
    glm::dmat3 alpha;
    if (!s.valid || !membrane_compliance(c, springs, s, double(m.area), h2, alpha)) return glm::dvec3(0.0);
    return glm::dvec3(s.eu, s.ev, alpha[2][2] > 0.0 ? s.gamma : 0.0) + alpha * lambda;
}

}  // namespace clothsim
