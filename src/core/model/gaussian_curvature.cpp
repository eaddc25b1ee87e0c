#include "model/gaussian_curvature.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace clothsim {

namespace {

double corner_angle(const glm::dvec3& e1, const glm::dvec3& e2) {
    return std::atan2(glm::length(glm::cross(e1, e2)), glm::dot(e1, e2));
}

}  // namespace

std::optional<HingeResponse> hinge_response(const std::vector<glm::dvec3>& rest, const Hinge& h, glm::dvec3 u_axis) {
    const glm::dvec3 x0 = rest[h.v[0]];
    const glm::dvec3 edge = rest[h.v[1]] - x0;
    const glm::dvec3 n0 = glm::cross(edge, rest[h.v[2]] - x0), n1 = glm::cross(rest[h.v[3]] - x0, edge);
    const double a0 = 0.5 * glm::length(n0), a1 = 0.5 * glm::length(n1);
    if (!(a0 > 0.0) || !(a1 > 0.0)) return std::nullopt;
    const glm::dvec3 n = n0 / (2.0 * a0);
    glm::dvec3 u = u_axis - glm::dot(u_axis, n) * n;
    if (!(glm::length(u) > 1e-9 * glm::length(u_axis))) return std::nullopt;
    u = glm::normalize(u);
    const glm::dvec3 v = glm::cross(n, u);
    HingeResponse r;
    // The rest dihedral angle's sine, |n0 x n1| / (|n0| |n1|).
    r.flat = glm::length(glm::cross(n0, n1)) <= 1e-6 * 4.0 * a0 * a1;
    r.area = a0 + a1;
    // With the hinge's own (float) cotangent weights, as its energy uses them.
    for (int i = 0; i < 4; ++i) {
        const glm::dvec3 p = rest[h.v[i]] - x0;
        const double pu = glm::dot(p, u), pv = glm::dot(p, v);
        r.alpha += 0.5 * double(h.c[i]) * pu * pu;
        r.beta += 0.5 * double(h.c[i]) * pv * pv;
    }
    return r;
}

GaussianCurvature gaussian_curvature(const std::vector<glm::dvec3>& rest,
                                     const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                     const std::vector<Hinge>& hinges, glm::dvec3 u_axis) {
    GaussianCurvature term;
    double cross_u = 0.0, cross_v = 0.0, area = 0.0;
    for (const Hinge& h : hinges) {
        const std::optional<HingeResponse> r = hinge_response(rest, h, u_axis);
        if (!r) continue;
        if (!r->flat) return term;  // a bent hinge's term would pull at rest
        cross_u += double(h.weight_u) * r->alpha * r->beta;
        cross_v += double(h.weight_v) * r->alpha * r->beta;
    }
    glm::dvec3 normal(0.0);
    for (const auto& t : triangles) {
        const glm::dvec3 n = glm::cross(rest[t[1]] - rest[t[0]], rest[t[2]] - rest[t[0]]);
        area += 0.5 * glm::length(n);
        normal += n;
    }
    if (!(area > 0.0) || !(glm::length(normal) > 0.0)) return term;
    find_rim(term, triangles, rest.size());
    // The hinges couple the curvatures over the whole area, the angle defects measure K at the interior vertices
    // only (a rim strip of about half a spacing is left out): the term's weight is the hinges' coupling over the
    // area whose K the defects measure, so that a uniform curvature's coupling cancels. That area is the
    // defects' sum over K for the rest shape lifted to z = 0.5 kappa (x^2 + y^2) off its plane (K = kappa^2).
    const glm::dvec3 n = glm::normalize(normal);
    const glm::dvec3 e1 = glm::normalize(std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1.0, 0.0, 0.0)) : glm::cross(n, glm::dvec3(0.0, 1.0, 0.0)));
    const glm::dvec3 e2 = glm::cross(n, e1);
    double size = 0.0;
    for (const glm::dvec3& p : rest) size = std::max(size, glm::length(p - rest[0]));
    const double kappa = 1e-3 / std::max(size, 1e-12);  // slopes of 1e-3: K within 1e-6 of kappa^2
    DVec3Array lifted;
    lifted.resize(rest.size());
    for (std::size_t i = 0; i < rest.size(); ++i) {
        const glm::dvec3 q = rest[i] - rest[0];
        const double x = glm::dot(q, e1), y = glm::dot(q, e2);
        lifted.set(i, rest[i] + n * (0.5 * kappa * (x * x + y * y)));
    }
    double angles = 0.0;
    for (const auto& [a, p, q] : term.rim_corners) {
        const glm::dvec3 xa = lifted.get(a);
        angles += corner_angle(lifted.get(p) - xa, lifted.get(q) - xa);
    }
    const double defects = angles - term.offset;  // the interior vertices' angle defects' sum (Gauss-Bonnet)
    const double measured = defects / (kappa * kappa);
    // A single plane's mesh measures 0.8 to 1 of its area; another (flat pieces in several planes) keeps the area.
    const double k_area = measured > 0.5 * area && measured <= area * (1.0 + 1e-6) ? measured : area;
    term.weight_u = float(cross_u / k_area);
    term.weight_v = float(cross_v / k_area);
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
