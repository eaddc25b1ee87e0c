#include "model/gaussian_curvature.hpp"

#include <glm/geometric.hpp>

#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace clothsim {

GaussianCurvature gaussian_curvature(const std::vector<glm::dvec3>& rest,
                                     const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                     const std::vector<Hinge>& hinges, glm::dvec3 u_axis) {
    GaussianCurvature term;
    double cross_u = 0.0, cross_v = 0.0, area = 0.0;
    for (const Hinge& h : hinges) {
        const glm::dvec3 x0 = rest[h.v[0]];
        const glm::dvec3 edge = rest[h.v[1]] - x0;
        const glm::dvec3 n0 = glm::cross(edge, rest[h.v[2]] - x0), n1 = glm::cross(rest[h.v[3]] - x0, edge);
        const double a0 = 0.5 * glm::length(n0), a1 = 0.5 * glm::length(n1);
        if (!(a0 > 0.0) || !(a1 > 0.0)) continue;
        // The rest dihedral angle, |n0 x n1| / (|n0| |n1|): a bent hinge's term would pull at rest.
        if (glm::length(glm::cross(n0, n1)) > 1e-6 * 4.0 * a0 * a1) return term;
        // The hinge's plane, u_axis projected on it, and the curvature's weights alpha and beta with the hinge's
        // own (float) cotangent weights, as its energy uses them.
        const glm::dvec3 n = glm::normalize(n0);
        glm::dvec3 u = u_axis - glm::dot(u_axis, n) * n;
        if (!(glm::length(u) > 1e-9)) continue;
        u = glm::normalize(u);
        const glm::dvec3 v = glm::cross(n, u);
        double alpha = 0.0, beta = 0.0;
        for (int i = 0; i < 4; ++i) {
            const glm::dvec3 p = rest[h.v[i]] - x0;
            const double pu = glm::dot(p, u), pv = glm::dot(p, v);
            alpha += 0.5 * double(h.c[i]) * pu * pu;
            beta += 0.5 * double(h.c[i]) * pv * pv;
        }
        cross_u += double(h.weight_u) * alpha * beta;
        cross_v += double(h.weight_v) * alpha * beta;
        area += (a0 + a1) / 3.0;  // each triangle a third in each of its (up to) three hinges
    }
    if (!(area > 0.0)) return term;
    term.weight_u = float(cross_u / area);
    term.weight_v = float(cross_v / area);
    find_rim(term, triangles, rest.size());
    return term;
}

void find_rim(GaussianCurvature& term, const std::vector<std::array<std::uint32_t, 3>>& triangles, std::size_t particles) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (const auto& t : triangles) {
        for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
    }
    std::vector<char> rim(particles, 0), used(particles, 0);
    for (const auto& [edge, count] : uses) {
        used[edge.first] = used[edge.second] = 1;
        if (count == 1) rim[edge.first] = rim[edge.second] = 1;
    }
    term.rim_corners.clear();
    for (const auto& t : triangles) {
        for (int k = 0; k < 3; ++k) {
            if (rim[t[k]]) term.rim_corners.push_back({t[k], t[(k + 1) % 3], t[(k + 2) % 3]});
        }
    }
    std::size_t interior = 0;
    for (std::size_t i = 0; i < particles; ++i) interior += used[i] && !rim[i];
    term.offset = std::numbers::pi * double(triangles.size()) - 2.0 * std::numbers::pi * double(interior);
}

namespace {

double corner_angle(const glm::dvec3& e1, const glm::dvec3& e2) {
    return std::atan2(glm::length(glm::cross(e1, e2)), glm::dot(e1, e2));
}

}  // namespace

template <class F>
void accumulate_gaussian_forces(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                                BasicVec3Array<F>& force) {
    using Vec = glm::vec<3, F>;
    visit_gaussian_forces(topology, position, springs, [&](std::uint32_t i, const glm::dvec3& f) { force.add(i, Vec(f)); });
}

double gaussian_energy(const Topology& topology, const DVec3Array& position, const SpringSettings& springs) {
    const double c = gaussian_coefficient(topology.gaussian, springs);
    if (c == 0.0 || topology.gaussian.rim_corners.empty()) return 0.0;
    double angles = 0.0;
    for (const auto& [a, p, q] : topology.gaussian.rim_corners) {
        const glm::dvec3 xa = position.get(a);
        angles += corner_angle(position.get(p) - xa, position.get(q) - xa);
    }
    return c * (topology.gaussian.offset - angles);
}

template void accumulate_gaussian_forces<float>(const Topology&, const DVec3Array&, const SpringSettings&, Vec3Array&);
template void accumulate_gaussian_forces<double>(const Topology&, const DVec3Array&, const SpringSettings&, DVec3Array&);

}  // namespace clothsim
