// A mesh cloth's constant-strain membrane triangles (spring.hpp: Membrane): the material's tensor, each
// triangle's strains, forces and energy, and the arithmetic every solver path shares (the list path's
// accumulate_spring_forces, the element gather, XPBD, implicit Euler's tangent, projective's gradient).
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include "model/forces.hpp"

#include <glm/geometric.hpp>

#include <cmath>

namespace clothsim {

// The membrane's plane-stress tensor in the warp / weft frame (N/m): C11 along u, C22 along v, C12 their
// coupling, C66 the shear (on the engineering shear gamma). The grid's own continuum (material.hpp,
// SpringConstants): C12 = C66 = G, the Cauchy relation of its lattice, and C11, C22 chosen so that uniaxial
// tension with the other direction free, C11 - C12^2 / C22 along u and C22 - C12^2 / C11 along v, is the
// material's stretch. So a mesh cloth and a grid cloth of one material store the same energy at one strain.
struct MembraneTensor {
    double c11 = 0.0, c22 = 0.0, c12 = 0.0, c66 = 0.0;
};
inline MembraneTensor membrane_tensor(double stretch_u, double stretch_v, double shear) {
    if (!(stretch_u > 0.0) || !(stretch_v > 0.0)) return {stretch_u, stretch_v, 0.0, shear};
    // C11 C22 - G^2 = s_u C22 = s_v C11: C11 = r C22 with r = s_u / s_v, and r C22^2 - s_u C22 - G^2 = 0.
    const double r = stretch_u / stretch_v;
    const double c22 = (stretch_u + std::sqrt(stretch_u * stretch_u + 4.0 * r * shear * shear)) / (2.0 * r);
    return {r * c22, c22, shear, shear};
}
inline MembraneTensor membrane_tensor(const SpringSettings& springs) {
    return membrane_tensor(springs.structural.x, springs.structural.y, springs.shear);
}

// A membrane's deformed warp or weft direction w = sum_i b_i x_i, in double, relative to its corner 0 (the
// weights sum to 0): b_1 (x_1 - x_0) + b_2 (x_2 - x_0).
inline glm::dvec3 membrane_direction(const DVec3Array& position, const Membrane& m, const std::array<float, 3>& b) {
    const glm::dvec3 o = position.get(m.v[0]);
    return double(b[1]) * (position.get(m.v[1]) - o) + double(b[2]) * (position.get(m.v[2]) - o);
}

// A membrane's state at some positions: its directions, their lengths, its strains and its stresses
// sigma_u = C11 t_u(e_u) + C12 e_v, sigma_v = C22 t_v(e_v) + C12 e_u, tau = C66 gamma (t a curve's stretch term,
// stretch_curve.hpp, on a rest length of 1), all in double. `valid` is false when a direction has collapsed
// (|w| <= 1e-12): the membrane then contributes nothing rather than NaN.
struct MembraneStrain {
    glm::dvec3 wu{0.0}, wv{0.0};
    double lu = 0.0, lv = 0.0, eu = 0.0, ev = 0.0, gamma = 0.0;
    double sigma_u = 0.0, sigma_v = 0.0, tau = 0.0;
    bool valid = false;
};
inline MembraneStrain membrane_strain(const DVec3Array& position, const Membrane& m, const MembraneTensor& c,
                                      const SpringSettings& springs) {
    MembraneStrain s;
    s.wu = membrane_direction(position, m, m.bu);
    s.wv = membrane_direction(position, m, m.bv);
    const double qu = glm::dot(s.wu, s.wu), qv = glm::dot(s.wv, s.wv);
    s.lu = std::sqrt(qu);
    s.lv = std::sqrt(qv);
    if (!(s.lu > 1e-12) || !(s.lv > 1e-12)) return s;
    s.valid = true;
    // |w| - 1 as (|w|^2 - 1) / (|w| + 1): the small strain keeps its relative precision.
    s.eu = (qu - 1.0) / (s.lu + 1.0);
    s.ev = (qv - 1.0) / (s.lv + 1.0);
    s.gamma = glm::dot(s.wu, s.wv);
    s.sigma_u = c.c11 * springs.membrane_curve[0].stretch_term(s.eu, 1.0) + c.c12 * s.ev;
    s.sigma_v = c.c22 * springs.membrane_curve[1].stretch_term(s.ev, 1.0) + c.c12 * s.eu;
    s.tau = c.c66 * s.gamma;
    return s;
}

// The corner forces f_i = bu_i p_u + bv_i p_v of a membrane (the energy's negative gradient:
// d e_u / d x_i = bu_i w_u / |w_u|, d gamma / d x_i = bu_i w_v + bv_i w_u), with
// p_u = -A (sigma_u w_u / |w_u| + tau w_v) and p_v = -A (sigma_v w_v / |w_v| + tau w_u), computed in double
// and rounded once to the force type T. Every force path adds bu_i p_u, then bv_i p_v, to corner i.
// From a valid strain s of a membrane of rest area `area`.
template <class T>
inline void membrane_forces(const MembraneStrain& s, double area, glm::vec<3, T>& pu, glm::vec<3, T>& pv) {
    const double a = -area;
    pu = glm::vec<3, T>(a * ((s.sigma_u / s.lu) * s.wu + s.tau * s.wv));
    pv = glm::vec<3, T>(a * ((s.sigma_v / s.lv) * s.wv + s.tau * s.wu));
}
template <class T>
inline bool membrane_forces(const DVec3Array& position, const Membrane& m, const MembraneTensor& c,
                            const SpringSettings& springs, glm::vec<3, T>& pu, glm::vec<3, T>& pv) {
    const MembraneStrain s = membrane_strain(position, m, c, springs);
    if (!s.valid) return false;
    membrane_forces(s, double(m.area), pu, pv);
    return true;
}

// A membrane's energy A (C11 U_u(e_u) + C22 U_v(e_v) + C12 e_u e_v + 0.5 C66 gamma^2) (J), each U a spring's
// (spring_energy, on a rest length of 1); 0 for a collapsed one.
inline double membrane_energy(const MembraneStrain& s, double area, const MembraneTensor& c, const SpringSettings& springs) {
    if (!s.valid) return 0.0;
    return area * (spring_energy(c.c11, springs.membrane_curve[0], s.eu, 1.0) +
                   spring_energy(c.c22, springs.membrane_curve[1], s.ev, 1.0) + c.c12 * s.eu * s.ev +
                   0.5 * c.c66 * s.gamma * s.gamma);
}
inline double membrane_energy(const DVec3Array& position, const Membrane& m, const MembraneTensor& c,
                              const SpringSettings& springs) {
    return membrane_energy(membrane_strain(position, m, c, springs), double(m.area), c, springs);
}

}  // namespace clothsim
