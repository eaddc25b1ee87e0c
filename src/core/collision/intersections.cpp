#include "clothsim/intersections.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace clothsim {

bool segment_meets_triangle(const glm::dvec3& p, const glm::dvec3& q, const glm::dvec3& a, const glm::dvec3& b,
                            const glm::dvec3& c) {
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double sp = glm::dot(n, p - a), sq = glm::dot(n, q - a);
    if ((sp > 0.0 && sq > 0.0) || (sp < 0.0 && sq < 0.0) || (sp == 0.0 && sq == 0.0)) return false;
    const glm::dvec3 x = p + (sp / (sp - sq)) * (q - p);
    const double la = glm::dot(glm::cross(b - x, c - x), n), lb = glm::dot(glm::cross(c - x, a - x), n),
                 lc = glm::dot(glm::cross(a - x, b - x), n);
    return la >= 0.0 && lb >= 0.0 && lc >= 0.0;
}

bool triangles_intersect(const std::array<glm::dvec3, 3>& t, const std::array<glm::dvec3, 3>& u) {
    for (int e = 0; e < 3; ++e) {
        if (segment_meets_triangle(t[e], t[(e + 1) % 3], u[0], u[1], u[2])) return true;
        if (segment_meets_triangle(u[e], u[(e + 1) % 3], t[0], t[1], t[2])) return true;
    }
    return false;
}

std::size_t intersecting_triangle_pairs(const Topology& topology, const std::vector<glm::vec3>& position) {
    const auto& tris = topology.triangles;
    std::vector<std::array<glm::dvec3, 3>> corner;
    std::vector<glm::dvec3> lo, hi;
    std::vector<std::size_t> kept;  // triangles with finite corners
    corner.reserve(tris.size());
    for (std::size_t k = 0; k < tris.size(); ++k) {
        std::array<glm::dvec3, 3> c;
        bool finite = true;
        for (int v = 0; v < 3; ++v) {
            c[v] = glm::dvec3(position[tris[k][v]]);
            finite = finite && std::isfinite(c[v].x) && std::isfinite(c[v].y) && std::isfinite(c[v].z);
        }
        if (!finite) continue;
        corner.push_back(c);
        lo.push_back(glm::min(c[0], glm::min(c[1], c[2])));
        hi.push_back(glm::max(c[0], glm::max(c[1], c[2])));
        kept.push_back(k);
    }
    const std::size_t m = corner.size();
    std::vector<std::size_t> order(m);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return lo[a].x < lo[b].x; });
    std::size_t count = 0;
    for (std::size_t u = 0; u < m; ++u) {
        const std::size_t a = order[u];
        for (std::size_t v = u + 1; v < m && lo[order[v]].x <= hi[a].x; ++v) {
            const std::size_t b = order[v];
            if (lo[b].y > hi[a].y || lo[a].y > hi[b].y || lo[b].z > hi[a].z || lo[a].z > hi[b].z) continue;
            const auto& ta = tris[kept[a]];
            const auto& tb = tris[kept[b]];
            bool shared = false;
            for (int i = 0; i < 3; ++i) {
                for (int j = 0; j < 3; ++j) shared = shared || ta[i] == tb[j];
            }
            if (!shared && triangles_intersect(corner[a], corner[b])) ++count;
        }
    }
    return count;
}

}  // namespace clothsim
