// The mesh cloth's checks and model (cloth_mesh.hpp).
#include "clothsim/cloth_mesh.hpp"

#include "clothsim/scene.hpp"
#include "clothsim/shapes/mesh.hpp"
#include "model/gaussian_curvature.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace clothsim {
namespace {

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | b;
}

// Every undirected edge with the triangles that have it (one or two once the mesh is checked), in the order
// the edges first appear.
struct EdgeUse {
    std::uint32_t a = 0, b = 0;     // as the first triangle runs it
    std::uint32_t triangle[2] = {0, 0};
    int count = 0;
    bool same_direction = false;    // the second triangle runs it a -> b too
};
std::vector<EdgeUse> edge_uses(const Triangles& triangles, std::uint32_t* third_triangle = nullptr) {
    std::vector<EdgeUse> edges;
    std::unordered_map<std::uint64_t, std::uint32_t> index;
    index.reserve(triangles.size() * 2);
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
            const auto [it, added] = index.try_emplace(edge_key(a, b), static_cast<std::uint32_t>(edges.size()));
            if (added) {
                edges.push_back({a, b, {t, 0}, 1, false});
                continue;
            }
            EdgeUse& e = edges[it->second];
            if (e.count == 1) {
                e.triangle[1] = t;
                e.same_direction = e.a == a;
            } else if (third_triangle && e.count == 2) {
                *third_triangle = t;
            }
            ++e.count;
        }
    }
    return edges;
}

double triangle_area(const std::vector<glm::dvec3>& rest, const std::array<std::uint32_t, 3>& t) {
    return 0.5 * glm::length(glm::cross(rest[t[1]] - rest[t[0]], rest[t[2]] - rest[t[0]]));
}

// 0-based, as pins count vertices, with the OBJ file's 1-based index.
std::string vertex_name(std::size_t i) { return "vertex " + std::to_string(i) + " (OBJ index " + std::to_string(i + 1) + ")"; }

std::string show(glm::dvec3 p) {
    std::ostringstream out;
    out.precision(6);
    out << "(" << p.x << ", " << p.y << ", " << p.z << ")";
    return out.str();
}

// The angle's cotangent at corner p of triangle (p, q, r): cos / sin from the dot and cross products.
double cotangent(glm::dvec3 p, glm::dvec3 q, glm::dvec3 r) {
    const glm::dvec3 a = q - p, b = r - p;
    return glm::dot(a, b) / glm::length(glm::cross(a, b));
}

}  // namespace

std::vector<glm::dvec3> placed_cloth_vertices(const ClothSettings& cloth) {
    std::vector<glm::dvec3> out;
    if (!cloth.mesh_data) return out;
    const glm::dmat3 turn = rotation_matrix(glm::dvec3(cloth.mesh_rotation));
    const double scale = cloth.mesh_scale;
    const glm::dvec3 origin(cloth.origin);
    out.reserve(cloth.mesh_data->vertices().size());
    for (const glm::dvec3& v : cloth.mesh_data->vertices()) out.push_back(turn * (v * scale) + origin);
    return out;
}

std::string cloth_mesh_problem(const std::vector<glm::dvec3>& vertices, const Triangles& triangles) {
    if (triangles.empty()) return "it has no triangles";
    const std::size_t n = vertices.size();
    double extent = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 p = vertices[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            return vertex_name(i) + " is not finite";
        }
        extent = std::max({extent, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    }
    std::vector<std::uint8_t> used(n, 0);
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        const auto& tri = triangles[t];
        for (std::uint32_t i : tri) {
            if (i >= n) return "triangle " + std::to_string(t) + " names vertex " + std::to_string(i) + " of " + std::to_string(n);
            used[i] = 1;
        }
        const std::string corners = " (vertices " + std::to_string(tri[0]) + ", " + std::to_string(tri[1]) + ", " +
                                    std::to_string(tri[2]) + ")";
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
            return "triangle " + std::to_string(t) + corners + " repeats a vertex";
        }
        const glm::dvec3 a = vertices[tri[0]], b = vertices[tri[1]], c = vertices[tri[2]];
        const double twice_area = glm::length(glm::cross(b - a, c - a));
        const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
        // No area, relative to its longest edge: a sliver 1e-6 as high as it is long has no direction to bend in.
        if (!(twice_area > 1e-6 * longest * longest)) {
            return "triangle " + std::to_string(t) + corners + " is degenerate (no area)";
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (!used[i]) return vertex_name(i) + " is in no triangle";
    }
    // Two vertices at one place, within 1e-9 of the mesh's extent: sorted by position, neighbours compared.
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
        const glm::dvec3 p = vertices[i], q = vertices[j];
        return p.x != q.x ? p.x < q.x : p.y != q.y ? p.y < q.y : p.z < q.z;
    });
    const double tolerance = 1e-9 * std::max(extent, 1e-300);
    std::pair<std::uint32_t, std::uint32_t> duplicate{0, 0};  // the pair of the lowest index
    for (std::size_t k = 0; k < n; ++k) {
        for (std::size_t l = k + 1; l < n && vertices[order[l]].x - vertices[order[k]].x <= tolerance; ++l) {
            const std::pair<std::uint32_t, std::uint32_t> pair = std::minmax(order[k], order[l]);
            if (glm::length(vertices[order[l]] - vertices[order[k]]) <= tolerance &&
                (duplicate.second == 0 || pair < duplicate)) {
                duplicate = pair;
            }
        }
    }
    if (const auto [i, j] = duplicate; j != 0) {
        return "vertices " + std::to_string(i) + " and " + std::to_string(j) + " (OBJ indices " + std::to_string(i + 1) +
               " and " + std::to_string(j + 1) + ") are duplicates, both at " + show(vertices[i]) +
               ": weld them (a seam of duplicate vertices leaves the cloth in pieces)";
    }
    std::uint32_t third = 0;
    const std::vector<EdgeUse> edges = edge_uses(triangles, &third);
    for (const EdgeUse& e : edges) {
        const std::string edge = "edge (" + std::to_string(std::min(e.a, e.b)) + ", " + std::to_string(std::max(e.a, e.b)) + ")";
        if (e.count > 2) {
            return "non-manifold " + edge + " at " + vertex_name(std::min(e.a, e.b)) + ": it is in " +
                   std::to_string(e.count) + " triangles (" + std::to_string(e.triangle[0]) + ", " +
                   std::to_string(e.triangle[1]) + ", " + std::to_string(third) + ", ...); allowed: at most 2";
        }
        if (e.count == 2 && e.same_direction) {
            return "triangles " + std::to_string(e.triangle[0]) + " and " + std::to_string(e.triangle[1]) + " run " + edge +
                   " the same way: their faces are not oriented alike";
        }
    }
    // A vertex where two sheets meet at a point: its triangles, joined across the edges at it, make more than
    // one fan.
    std::vector<std::uint32_t> first(n + 1, 0), around;
    for (const auto& tri : triangles) {
        for (std::uint32_t i : tri) ++first[i + 1];
    }
    for (std::size_t i = 0; i < n; ++i) first[i + 1] += first[i];
    around.resize(first[n]);
    {
        std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
        for (std::uint32_t t = 0; t < triangles.size(); ++t) {
            for (std::uint32_t i : triangles[t]) around[fill[i]++] = t;
        }
    }
    std::unordered_map<std::uint64_t, std::uint32_t> edge_of;
    edge_of.reserve(edges.size());
    for (std::uint32_t e = 0; e < edges.size(); ++e) edge_of.emplace(edge_key(edges[e].a, edges[e].b), e);
    std::vector<std::uint32_t> parent;
    for (std::uint32_t v = 0; v < n; ++v) {
        const std::uint32_t begin = first[v], count = first[v + 1] - first[v];
        if (count < 2) continue;
        parent.resize(count);
        std::iota(parent.begin(), parent.end(), 0u);
        auto find = [&](std::uint32_t i) {
            while (parent[i] != i) i = parent[i] = parent[parent[i]];
            return i;
        };
        auto local = [&](std::uint32_t t) {
            return static_cast<std::uint32_t>(std::find(around.begin() + begin, around.begin() + begin + count, t) -
                                              (around.begin() + begin));
        };
        for (std::uint32_t k = 0; k < count; ++k) {
            for (std::uint32_t w : triangles[around[begin + k]]) {
                if (w == v) continue;
                const EdgeUse& e = edges[edge_of.at(edge_key(v, w))];
                if (e.count == 2) parent[find(local(e.triangle[0]))] = find(local(e.triangle[1]));
            }
        }
        std::uint32_t fans = 0;
        for (std::uint32_t k = 0; k < count; ++k) fans += find(k) == k;
        if (fans > 1) {
            return "non-manifold " + vertex_name(v) + ": " + std::to_string(fans) +
                   " sheets of triangles meet there at a point only";
        }
    }
    return "";
}

std::vector<Spring> membrane_springs(const std::vector<glm::dvec3>& rest, const Triangles& triangles,
                                     glm::dvec3 u_axis, glm::dvec2 stretch, MembraneModel membrane) {
    const glm::dvec3 u = glm::normalize(u_axis);
    std::vector<Spring> springs;
    for (const EdgeUse& e : edge_uses(triangles)) {
        const glm::dvec3 d = rest[e.b] - rest[e.a];
        const double length2 = glm::dot(d, d);
        // van Gelder 1998: k_e = E sum_T A_T / |e|^2, with E = E_u cos^2 + E_v sin^2 of the edge's angle to u.
        const double cu = std::clamp(glm::dot(d, u) * glm::dot(d, u) / length2, 0.0, 1.0);
        const double area = triangle_area(rest, triangles[e.triangle[0]]) + (e.count == 2 ? triangle_area(rest, triangles[e.triangle[1]]) : 0.0);
        const double k = area / length2 * (stretch.x * cu + stretch.y * (1.0 - cu));
        // The rest length in the spring kernels' arithmetic, as the grid's (cloth_builder.cpp); k = E_u w.
        const auto level = static_cast<std::uint8_t>(1 + std::lround(cu * kWarpLevels));
        springs.push_back({e.a, e.b, glm::length(glm::vec3(d)), SpringKind::Structural, Axis::U, level,
                           membrane == MembraneModel::Triangles ? 0.0f : static_cast<float>(k / stretch.x)});
    }
    return springs;
}

std::vector<Membrane> membrane_triangles(const std::vector<glm::dvec3>& rest, const Triangles& triangles,
                                         glm::dvec3 u_axis) {
    const glm::dvec3 u_dir = glm::normalize(u_axis);
    std::vector<Membrane> out;
    out.reserve(triangles.size());
    for (const auto& t : triangles) {
        const glm::dvec3 e1 = rest[t[1]] - rest[t[0]], e2 = rest[t[2]] - rest[t[0]];
        const glm::dvec3 n = glm::normalize(glm::cross(e1, e2));
        // The warp in the triangle's plane: u_axis projected on it (an edge where u_axis is the normal).
        glm::dvec3 u = u_dir - glm::dot(u_dir, n) * n;
        u = glm::length(u) > 1e-6 ? glm::normalize(u) : glm::normalize(e1);
        const glm::dvec3 v = glm::cross(n, u);
        // The rest edges in the (u, v) frame, D_m = [a b]; w = D_s D_m^-1 (det = 2 A > 0: (u, v, n) is right-handed).
        const glm::dvec2 a(glm::dot(e1, u), glm::dot(e1, v)), b(glm::dot(e2, u), glm::dot(e2, v));
        const double det = a.x * b.y - b.x * a.y;
        Membrane m;
        m.v = t;
        const double bu1 = b.y / det, bu2 = -a.y / det, bv1 = -b.x / det, bv2 = a.x / det;
        m.bu = {float(-(bu1 + bu2)), float(bu1), float(bu2)};
        m.bv = {float(-(bv1 + bv2)), float(bv1), float(bv2)};
        m.area = float(0.5 * det);
        out.push_back(m);
    }
    return out;
}

std::vector<double> vertex_areas(const std::vector<glm::dvec3>& rest, const Triangles& triangles) {
    std::vector<double> area(rest.size(), 0.0);
    for (const auto& t : triangles) {
        // Twice the area over 6 (not triangle_area / 3): the masses' rounding as recorded (test_stepper's hashes).
        const double third = glm::length(glm::cross(rest[t[1]] - rest[t[0]], rest[t[2]] - rest[t[0]])) / 6.0;
        for (std::uint32_t i : t) area[i] += third;
    }
    return area;
}

namespace {

// The material form's hinge weights, so that the mesh under a uniform curvature stores the material's plate energy
// along u and along v: B_11 = bending.x and B_22 = bending.y (their coupling B_12 is the Gaussian-curvature term's,
// gaussian_curvature.hpp). A curvature along an edge also kinks it (the linear interpolation), so splitting a
// hinge's B by its edge's angle lets a curvature along u reach the hinges weighted for v (on irregular Delaunay
// triangles B_11 = 0.70 B_u + 0.37 B_v, and 1.07 B for isotropic bending). Each hinge is split instead by what it
// senses, s = t^2 / (t^2 + (1 - t)^2) with t = alpha^2 / (alpha^2 + beta^2) (hinge_response), its shares
// w s and w (1 - s) of w = 1 / (A_0 + A_1); the mesh then stores B_11 = M_11 B_u + M_12 B_v, B_22 = M_21 B_u +
// M_22 B_v with M from sum w s alpha^2 and the like over its area, and the weights taken through M^-1 make it the
// identity, for any bending live (k stays linear in bending.x and bending.y). The inverse's small off-diagonal
// terms give some hinges a negative share: a hinge's k is kept at 0 or more (stiffness_of), which it is for any
// ratio of bending.y to bending.x within about 1/13 to 7 (measured fabrics: 0.5 to 2). A degenerate or singular
// mesh keeps the edges' split.
void calibrate_hinges(const std::vector<glm::dvec3>& rest, const Triangles& triangles, std::vector<Hinge>& hinges,
                      glm::dvec3 u_axis) {
    std::vector<std::array<double, 2>> share(hinges.size());  // per hinge: w s, w (1 - s)
    double m11 = 0.0, m12 = 0.0, m21 = 0.0, m22 = 0.0, area = 0.0;
    for (std::size_t i = 0; i < hinges.size(); ++i) {
        const Hinge& h = hinges[i];
        share[i] = {double(h.weight_u), double(h.weight_v)};
        const std::optional<HingeResponse> r = hinge_response(rest, h, u_axis);
        if (r && r->alpha * r->alpha + r->beta * r->beta > 0.0) {
            const double a2 = r->alpha * r->alpha, b2 = r->beta * r->beta;
            const double t = a2 / (a2 + b2);
            const double s = t * t / (t * t + (1.0 - t) * (1.0 - t));
            const double w = 1.0 / r->area;
            share[i] = {w * s, w * (1.0 - s)};
            m11 += share[i][0] * a2;
            m12 += share[i][1] * a2;
            m21 += share[i][0] * b2;
            m22 += share[i][1] * b2;
        }
    }
    for (const auto& t : triangles) area += triangle_area(rest, t);
    const double det = m11 * m22 - m12 * m21;
    if (!(area > 0.0) || !(det > 1e-6 * m11 * m22) || !std::isfinite(det)) return;
    // M / area, inverted: N = (M / area)^-1.
    const double n11 = area * m22 / det, n12 = -area * m12 / det, n21 = -area * m21 / det, n22 = area * m11 / det;
    for (std::size_t i = 0; i < hinges.size(); ++i) {
        hinges[i].weight_u = float(n11 * share[i][0] + n21 * share[i][1]);
        hinges[i].weight_v = float(n12 * share[i][0] + n22 * share[i][1]);
    }
}

}  // namespace

Topology mesh_topology(const std::vector<glm::dvec3>& rest, const Triangles& triangles, glm::dvec3 u_axis,
                       std::optional<glm::dvec2> stretch, MembraneModel membrane) {
    const bool material = stretch.has_value();
    const glm::dvec3 u = glm::normalize(u_axis);
    Topology t;
    t.mesh = true;
    t.material_weights = material;
    t.rows = 1;
    t.cols = static_cast<int>(rest.size());
    t.triangles = triangles;
    // cos^2 of an edge's angle to u_axis.
    auto along_u = [&](glm::dvec3 d) {
        const double c = glm::dot(d, u);
        return std::clamp(c * c / glm::dot(d, d), 0.0, 1.0);
    };
    const std::vector<EdgeUse> edges = edge_uses(triangles);
    if (material) t.springs = membrane_springs(rest, triangles, u_axis, *stretch, membrane);
    if (material && membrane == MembraneModel::Triangles) t.membranes = membrane_triangles(rest, triangles, u_axis);
    if (!material) {
        // The per-spring form: springs.structural along u for an edge nearer u, along v otherwise.
        for (const EdgeUse& e : edges) {
            const glm::dvec3 d = rest[e.b] - rest[e.a];
            const float rest_length = glm::length(glm::vec3(d));
            t.springs.push_back({e.a, e.b, rest_length, SpringKind::Structural, along_u(d) >= 0.5 ? Axis::U : Axis::V, 0, 1.0f});
        }
    }
    // Hinges on interior edges (Bergou et al. 2006): triangle 0 is (x0, x1, x2), triangle 1 (x0, x1, x3).
    for (const EdgeUse& e : edges) {
        if (e.count != 2) continue;
        auto opposite = [&](std::uint32_t tri) {
            for (std::uint32_t i : triangles[tri]) {
                if (i != e.a && i != e.b) return i;
            }
            return e.a;
        };
        Hinge h;
        h.v = {e.a, e.b, opposite(e.triangle[0]), opposite(e.triangle[1])};
        const glm::dvec3 x0 = rest[h.v[0]], x1 = rest[h.v[1]], x2 = rest[h.v[2]], x3 = rest[h.v[3]];
        const double a0 = cotangent(x0, x1, x2), a1 = cotangent(x0, x1, x3);  // at x0
        const double b0 = cotangent(x1, x0, x2), b1 = cotangent(x1, x0, x3);  // at x1
        h.c = {float(b0 + b1), float(a0 + a1), float(-(a0 + b0)), float(-(a1 + b1))};
        // B across the edge: an edge along u bends along v.
        const double cu = along_u(x1 - x0);
        const double w = material ? 1.0 / (triangle_area(rest, triangles[e.triangle[0]]) + triangle_area(rest, triangles[e.triangle[1]])) : 1.0;
        h.weight_u = float(w * (1.0 - cu));
        h.weight_v = float(w * cu);
        t.hinges.push_back(h);
    }
    if (material) calibrate_hinges(rest, triangles, t.hinges, u);
    t.gaussian = gaussian_curvature(rest, triangles, t.hinges, u);
    // Texture coordinates: the rest shape on u and on n x u, n the mean normal (by area).
    glm::dvec3 normal(0.0);
    for (const auto& c : triangles) normal += glm::cross(rest[c[1]] - rest[c[0]], rest[c[2]] - rest[c[0]]);
    glm::dvec3 across = glm::cross(normal, u);
    if (!(glm::length(across) > 1e-9 * glm::length(normal))) {
        across = glm::cross(u, std::abs(u.y) < 0.9 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0));
    }
    across = glm::normalize(across);
    t.uv.reserve(rest.size());
    for (const glm::dvec3& p : rest) t.uv.emplace_back(float(glm::dot(p - rest[0], u)), float(glm::dot(p - rest[0], across)));
    t.count_by_kind();
    return t;
}

std::vector<float> mesh_cloth_masses(const ClothSettings& cloth, const std::vector<double>& area) {
    double total = 0.0;
    for (double a : area) total += a;
    const double per_area = double(cloth.mass) / total;
    std::vector<float> mass(area.size());
    for (std::size_t i = 0; i < area.size(); ++i) {
        mass[i] = static_cast<float>(per_area * area[i]);
        // A mesh so small (or so light) that a vertex's share rounds to no mass in float cannot move.
        if (!(mass[i] > 0.0f && std::isfinite(1.0f / mass[i]))) {
            throw SceneError("cloth.mesh = \"" + cloth.mesh + "\": vertex " + std::to_string(i) + " carries " +
                             std::to_string(area[i]) + " m^2 of cloth, too little for a mass; allowed: a mesh whose "
                             "triangles are larger (cloth.mesh_scale scales it)");
        }
    }
    return mass;
}

std::string cloth_mesh_summary(const Topology& topology, std::size_t particles, double critical_substep) {
    float shortest = std::numeric_limits<float>::infinity();
    for (const Spring& s : topology.springs) shortest = std::min(shortest, s.rest_length);
    // One spring per edge; a hinge per interior edge.
    const std::size_t edges = topology.springs.size();
    std::ostringstream out;
    out.precision(3);
    out << "mesh: " << particles << " vertices, " << edges << " edges (" << edges - std::min(edges, topology.hinges.size())
        << " on the boundary), " << topology.triangles.size()
        << (topology.membranes.empty() ? " triangles" : " membrane triangles") << "; shortest edge " << shortest << " m";
    if (critical_substep > 0.0 && std::isfinite(critical_substep)) out << "; critical substep " << 1e3 * critical_substep << " ms";
    return out.str();
}

}  // namespace clothsim
