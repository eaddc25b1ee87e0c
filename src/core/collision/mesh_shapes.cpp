#include "clothsim/mesh_shapes.hpp"

#include "clothsim/overloaded.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace clothsim {

TriangleMesh icosphere(double radius, int subdivisions) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<glm::dvec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    std::vector<TriangleMesh::Triangle> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                             {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                             {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                             {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (glm::dvec3& p : v) p = glm::normalize(p);
    for (int level = 0; level < subdivisions; ++level) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middle;
        auto mid = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto found = middle.find(key);
            if (found != middle.end()) return found->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            const auto index = static_cast<std::uint32_t>(v.size() - 1);
            middle.emplace(key, index);
            return index;
        };
        std::vector<TriangleMesh::Triangle> next;
        next.reserve(4 * f.size());
        for (const auto& [a, b, c] : f) {
            const std::uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
            next.push_back({a, ab, ca});
            next.push_back({b, bc, ab});
            next.push_back({c, ca, bc});
            next.push_back({ab, bc, ca});
        }
        f = std::move(next);
    }
    for (glm::dvec3& p : v) p *= radius;
    return TriangleMesh(std::move(v), std::move(f));
}

TriangleMesh box_mesh(glm::dvec3 size) {
    const glm::dvec3 h = 0.5 * size;
    std::vector<glm::dvec3> v;
    for (int k = 0; k < 8; ++k) v.push_back({(k & 1) ? h.x : -h.x, (k & 2) ? h.y : -h.y, (k & 4) ? h.z : -h.z});
    // Corner k has x from bit 0, y from bit 1, z from bit 2; each face counter-clockwise from outside.
    std::vector<TriangleMesh::Triangle> f = {
        {1, 3, 7}, {1, 7, 5},  // +x
        {0, 4, 6}, {0, 6, 2},  // -x
        {2, 6, 7}, {2, 7, 3},  // +y
        {0, 1, 5}, {0, 5, 4},  // -y
        {4, 5, 7}, {4, 7, 6},  // +z
        {0, 2, 3}, {0, 3, 1},  // -z
    };
    return TriangleMesh(std::move(v), std::move(f));
}

TriangleMesh lathe(const std::vector<glm::dvec2>& profile, int slices) {
    std::vector<glm::dvec3> v;
    std::vector<TriangleMesh::Triangle> f;
    // Each profile point's ring: one vertex on the axis, else a number of vertices that grows with its radius
    // (`slices` at the largest, 12 at least), so a flat disc is made of rings of well-shaped triangles, not of
    // slivers from the centre.
    double widest = 0.0;
    for (glm::dvec2 q : profile) widest = std::max(widest, q.x);
    std::vector<std::uint32_t> first(profile.size()), count(profile.size());
    for (std::size_t i = 0; i < profile.size(); ++i) {
        first[i] = static_cast<std::uint32_t>(v.size());
        count[i] = profile[i].x <= 0.0 ? 1
                                       : static_cast<std::uint32_t>(std::clamp(
                                             static_cast<int>(std::ceil(slices * profile[i].x / widest)), 12, slices));
        for (std::uint32_t s = 0; s < count[i]; ++s) {
            const double a = 2.0 * std::numbers::pi * s / count[i];
            v.push_back({profile[i].x * std::cos(a), profile[i].y, -profile[i].x * std::sin(a)});
        }
    }
    for (std::size_t i = 0; i + 1 < profile.size(); ++i) {
        // Rings i and i + 1 zipped: step along whichever ring's next vertex comes first by angle.
        const std::uint32_t na = count[i], nb = count[i + 1];
        auto ring_a = [&](std::uint32_t k) { return first[i] + k % na; };
        auto ring_b = [&](std::uint32_t k) { return first[i + 1] + k % nb; };
        // Outward: the profile's direction turned clockwise in the (radius, height) plane, at the face's angle.
        const glm::dvec2 along = profile[i + 1] - profile[i];
        std::uint32_t ia = 0, ib = 0;
        while (ia < na || ib < nb) {
            const bool step_a = ib == nb || (ia < na && na > 1 &&
                                             static_cast<double>(ia + 1) / na < static_cast<double>(ib + 1) / nb);
            TriangleMesh::Triangle t = step_a ? TriangleMesh::Triangle{ring_a(ia), ring_a(ia + 1), ring_b(ib)}
                                              : TriangleMesh::Triangle{ring_a(ia), ring_b(ib + 1), ring_b(ib)};
            if (step_a) ++ia;
            else ++ib;
            if (na == 1 && step_a) continue;  // a pole does not step
            if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
            const glm::dvec3 centre = (v[t[0]] + v[t[1]] + v[t[2]]) / 3.0;
            const glm::dvec2 radial = glm::length(glm::dvec2(centre.x, centre.z)) > 0.0
                                          ? glm::normalize(glm::dvec2(centre.x, centre.z))
                                          : glm::dvec2(1.0, 0.0);
            const glm::dvec3 outward(along.y * radial.x, -along.x, along.y * radial.y);
            if (glm::dot(glm::cross(v[t[1]] - v[t[0]], v[t[2]] - v[t[0]]), outward) < 0.0) std::swap(t[1], t[2]);
            f.push_back(t);
        }
    }
    return TriangleMesh(std::move(v), std::move(f));
}

TriangleMesh round_table() {
    // The profile from the foot's centre out and up to the top's centre (metres). Flat parts are split into rings
    // about 2.5 cm apart, so no triangle is a long sliver from the axis (whose box would cover the whole disc,
    // and which every query near the centre would have to test).
    std::vector<glm::dvec2> p;
    auto flat = [&](double from, double to, double y) {
        const int steps = std::max(1, static_cast<int>(std::ceil(std::fabs(to - from) / 0.025)));
        for (int k = 0; k <= steps; ++k) p.push_back({from + (to - from) * k / steps, y});
    };
    flat(0.0, 0.26, 0.0);  // the foot
    for (glm::dvec2 q : {glm::dvec2{0.27, 0.01}, {0.26, 0.025}, {0.06, 0.04}, {0.035, 0.08}, {0.035, 0.66}, {0.06, 0.69}}) {
        p.push_back(q);
    }
    // The top, 6 cm thick: its underside out to the rim, a rim rounded with radius 3 cm (a cloth 4.5 cm between
    // particles wraps it with chords that sag 6 mm, inside a thickness of 8 mm), its top back to the axis.
    const double r = 0.5, rim = 0.03, middle = 0.73;
    flat(0.12, r - rim, middle - rim);
    for (int k = 1; k < 6; ++k) {  // 30 degrees apart: the rim's polygon lies within 1 mm of its circle
        const double a = -0.5 * std::numbers::pi + std::numbers::pi * k / 6.0;
        p.push_back({r - rim + rim * std::cos(a), middle + rim * std::sin(a)});
    }
    flat(r - rim, 0.0, middle + rim);
    return lathe(p, 128);  // the top's edge within 0.15 mm of its circle
}

std::optional<TriangleMesh> collider_surface(const Collider& collider) {
    // The shape's own mesh about its origin, then moved (and for a mesh turned and scaled) into place.
    auto moved = [](const TriangleMesh& local, auto&& place) {
        std::vector<glm::dvec3> v = local.vertices();
        for (glm::dvec3& p : v) p = place(p);
        return TriangleMesh(std::move(v), local.triangles());
    };
    return std::visit(
        Overloaded{
            [&](const SphereCollider& s) -> std::optional<TriangleMesh> {
                return moved(icosphere(s.radius, 3), [&](glm::dvec3 p) { return p + glm::dvec3(s.center); });
            },
            [&](const BoxCollider& b) -> std::optional<TriangleMesh> {
                return moved(box_mesh(glm::dvec3(b.size)), [&](glm::dvec3 p) { return p + glm::dvec3(b.center); });
            },
            [&](const CylinderCollider& c) -> std::optional<TriangleMesh> {
                const double r = c.radius, h = 0.5 * c.height;
                return moved(lathe({{0.0, -h}, {r, -h}, {r, h}, {0.0, h}}, 64),
                             [&](glm::dvec3 p) { return p + glm::dvec3(c.center); });
            },
            [&](const MeshCollider& m) -> std::optional<TriangleMesh> {
                if (!m.mesh) return std::nullopt;
                const PlacedMesh at = placed(m);
                return moved(*m.mesh, [&](glm::dvec3 p) { return at.to_world(p); });
            },
            [](const auto&) -> std::optional<TriangleMesh> { return std::nullopt; },
        },
        collider.shape);
}

}  // namespace clothsim
