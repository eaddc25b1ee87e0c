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

// Calls visit(i, f) for each force f (N, double) of the term on particle i, as accumulate_gaussian_forces adds them.
template <class Visit>
void visit_gaussian_forces(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                           Visit&& visit) {
    const double c = gaussian_coefficient(topology.gaussian, springs);
    if (c == 0.0) return;
    for (const auto& [a, p, q] : topology.gaussian.rim_corners) {
        const glm::dvec3 xa = position.get(a);
        const glm::dvec3 e1 = position.get(p) - xa, e2 = position.get(q) - xa;
        const glm::dvec3 normal = glm::cross(e1, e2);
        const double length = glm::length(normal);
        if (!(length > 0.0)) continue;
        const glm::dvec3 n = normal / length;
        const glm::dvec3 fp = (c / glm::dot(e1, e1)) * glm::cross(e1, n);
        const glm::dvec3 fq = (c / glm::dot(e2, e2)) * glm::cross(n, e2);
        visit(a, -(fp + fq));
        visit(p, fp);
        visit(q, fq);
    }
}

// Adds F = c grad(sum of rim corners' angles) to `force`: per rim corner (a, p, q) with e_1 = x_p - x_a,
// e_2 = x_q - x_a and n their unit normal, dphi/dx_p = (e_1 x n) / |e_1|^2, dphi/dx_q = (n x e_2) / |e_2|^2 and
// dphi/dx_a their negated sum; each computed in double and added in F, corner by corner in list order. A corner
// with no normal (a collapsed triangle) adds nothing.
template <class F>
void accumulate_gaussian_forces(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                                BasicVec3Array<F>& force);
// The term's energy, c (offset - sum of rim corners' angles) (J): 0 at any flat shape.
double gaussian_energy(const Topology& topology, const DVec3Array& position, const SpringSettings& springs);

}  // namespace clothsim
