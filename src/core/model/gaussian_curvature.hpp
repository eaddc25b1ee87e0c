// The Gaussian-curvature term of a flat mesh cloth's bending (spring.hpp: GaussianCurvature): the hinges'
// Poisson coupling taken out, so that a mesh bends as a woven fabric (and the grid's row and column bends) does,
// with no coupling between its two curvatures. A narrow strip then droops as the elastica instead of curving
// anticlastically (docs/MESH_CLOTH.md measures both). Every solver path adds its force explicitly: the list path
// (accumulate_spring_forces) and the element gather with the springs' forces, XPBD with the external ones,
// implicit Euler and projective through the list path's forces (neither takes it into its matrix).
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

namespace clothsim {

// A hinge's response to a uniform curvature of its rest shape: for z = 0.5 (a u^2 + b v^2) in the plane of its first
// triangle (u: u_axis projected on that plane, v across it), its sum_i c_i z_i is a alpha + b beta (m^2), exactly:
// the hinge's energy is quadratic. `flat`: its two rest triangles lie in one plane (within 1e-6 rad); `area` the
// two triangles' (m^2). Empty for a degenerate hinge (a triangle of no area, or one across u_axis).
struct HingeResponse {
    double alpha = 0.0, beta = 0.0, area = 0.0;
    bool flat = true;
};
std::optional<HingeResponse> hinge_response(const std::vector<glm::dvec3>& rest, const Hinge& hinge, glm::dvec3 u_axis);

// The term of a mesh with hinges `hinges` (built on `rest` with u_axis `u_axis`): its weights, B_12 per unit
// bending.x and bending.y of the hinges' energy for a uniform curvature of the rest shape (hinge_response: B_12 is
// sum k alpha beta over the mesh's area), and its rim (find_rim). No term (weights 0) when a hinge's rest shape is not flat: the
// energy -B_12 integral(K dA) is stationary only at a flat shape.
GaussianCurvature gaussian_curvature(const std::vector<glm::dvec3>& rest,
                                     const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                     const std::vector<Hinge>& hinges, glm::dvec3 u_axis);
// The rim corners and the offset of the term for `triangles` on `particles` vertices (again after a tear).
void find_rim(GaussianCurvature& term, const std::vector<std::array<std::uint32_t, 3>>& triangles, std::size_t particles);

// The term's coefficient c = B_12 (N m) for the bending stiffness in `springs`.
inline double gaussian_coefficient(const GaussianCurvature& term, const SpringSettings& springs) {
    return double(springs.bending.x) * term.weight_u + double(springs.bending.y) * term.weight_v;
}
// Whether `topology` has the term at `springs`' bending.
inline bool has_gaussian_term(const Topology& topology, const SpringSettings& springs) {
    return !topology.gaussian.rim_corners.empty() && gaussian_coefficient(topology.gaussian, springs) != 0.0;
}

// One rim corner's forces c grad(phi) on its vertices a, p, q at xa, xp, xq; false (and nothing written) for a
// corner with no normal (a collapsed triangle).
inline bool corner_forces(const glm::dvec3& xa, const glm::dvec3& xp, const glm::dvec3& xq, double c, glm::dvec3& fa,
                          glm::dvec3& fp, glm::dvec3& fq) {
    const glm::dvec3 e1 = xp - xa, e2 = xq - xa;
    // |e_1 x e_2|^2 by Lagrange's identity; e_1 x n = (e_1 (e_1.e_2) - e_2 |e_1|^2) / |e_1 x e_2| and
    // n x e_2 = (e_2 (e_1.e_2) - e_1 |e_2|^2) / |e_1 x e_2|: one square root and one division a corner.
    const double e11 = glm::dot(e1, e1), e22 = glm::dot(e2, e2), e12 = glm::dot(e1, e2);
    const double area2 = e11 * e22 - e12 * e12;
    if (!(area2 > 0.0)) return false;
    const double r = c / (std::sqrt(area2) * e11 * e22);
    fp = (r * e22) * (e1 * e12 - e2 * e11);
    fq = (r * e11) * (e2 * e12 - e1 * e22);
    fa = -(fp + fq);
    return true;
}

// Calls visit(i, f) for each force f (N, double) of the term on particle i, as accumulate_gaussian_forces adds them.
template <class Visit>
void visit_gaussian_forces(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                           Visit&& visit) {
    const double c = gaussian_coefficient(topology.gaussian, springs);
    if (c == 0.0) return;
    for (const auto& [a, p, q] : topology.gaussian.rim_corners) {
        glm::dvec3 fa, fp, fq;
        if (!corner_forces(position.get(a), position.get(p), position.get(q), c, fa, fp, fq)) continue;
        visit(a, fa);
        visit(p, fp);
        visit(q, fq);
    }
}

// Adds F = c grad(sum of rim corners' angles) to `force`: per rim corner (a, p, q) with e_1 = x_p - x_a,
// e_2 = x_q - x_a and n their unit normal, dphi/dx_p = (e_1 x n) / |e_1|^2, dphi/dx_q = (n x e_2) / |e_2|^2 and
// dphi/dx_a their negated sum (visit_gaussian_forces writes them without cross products); each computed in double and added in F, corner by corner in list order. A corner
// with no normal (a collapsed triangle) adds nothing.
template <class F>
void accumulate_gaussian_forces(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                                BasicVec3Array<F>& force);
// accumulate_gaussian_forces for the fast paths (the element gather, coloured XPBD): with the AVX-512 kernel
// (FastSolver's choice, so the tests run every kernel the CPU has) eight corners at a time in double, in
// visit_gaussian_forces' operations and order, each corner's forces then added in list order: bit-identical.
void accumulate_gaussian_forces_fast(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                                     Vec3Array& force);
// Rim corners [first, last) for the element gather: corner j's forces on a, p and q, rounded to float, at
// out[slot + 3 (j - first)] and the next two (zero for a collapsed corner); with the AVX-512 kernel eight at a time,
// bit-identical.
void gaussian_corner_forces(const GaussianCurvature& term, const DVec3Array& position, double c, std::size_t first,
                            std::size_t last, Vec3Array& out, std::size_t slot);
// The term's energy, c (offset - sum of rim corners' angles) (J): 0 at any flat shape.
double gaussian_energy(const Topology& topology, const DVec3Array& position, const SpringSettings& springs);

}  // namespace clothsim
