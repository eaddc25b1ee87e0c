#include "clothsim/mesh_shapes.hpp"

#include "clothsim/overloaded.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <unordered_map>
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

TriangleMesh isosurface(const std::function<double(glm::dvec3)>& field, glm::dvec3 lo, glm::dvec3 hi, double cell) {
    const glm::ivec3 n = glm::max(glm::ivec3(glm::ceil((hi - lo) / cell)), glm::ivec3(1)) + 1;  // grid points per axis
    auto index = [&](int x, int y, int z) { return (static_cast<std::uint64_t>(z) * n.y + y) * n.x + x; };
    auto point = [&](std::uint64_t g) {
        const auto x = static_cast<int>(g % n.x), y = static_cast<int>(g / n.x % n.y), z = static_cast<int>(g / n.x / n.y);
        return lo + glm::dvec3(x, y, z) * cell;
    };
    std::vector<double> value(static_cast<std::size_t>(n.x) * n.y * n.z);
    for (std::uint64_t g = 0; g < value.size(); ++g) {
        const double f = field(point(g));
        value[g] = std::abs(f) < 1e-12 ? 1e-12 : f;  // no grid point on the surface: every crossing is an edge's
    }
    std::vector<glm::dvec3> v;
    std::vector<TriangleMesh::Triangle> f;
    std::unordered_map<std::uint64_t, std::uint32_t> on_edge;  // grid edge (a, b), a < b -> its vertex
    auto vertex = [&](std::uint64_t a, std::uint64_t b) {
        if (a > b) std::swap(a, b);
        const auto [at, made] = on_edge.try_emplace(a * value.size() + b, static_cast<std::uint32_t>(v.size()));
        if (made) {
            const double t = std::clamp(value[a] / (value[a] - value[b]), 0.02, 0.98);
            v.push_back(point(a) + t * (point(b) - point(a)));
        }
        return at->second;
    };
    // A triangle on edges (in, out) of a tetrahedron, turned to face from its inside corners to its outside ones.
    auto emit = [&](std::array<std::uint32_t, 3> t, glm::dvec3 inside, glm::dvec3 outside) {
        if (glm::dot(glm::cross(v[t[1]] - v[t[0]], v[t[2]] - v[t[0]]), outside - inside) < 0.0) std::swap(t[1], t[2]);
        f.push_back(t);
    };
    // Kuhn's six tetrahedra of a cube: corners 0 and 7 (bits x = 1, y = 2, z = 4) and a path between them.
    constexpr int kAxes[6][2] = {{1, 2}, {1, 4}, {2, 1}, {2, 4}, {4, 1}, {4, 2}};
    for (int z = 0; z + 1 < n.z; ++z) {
        for (int y = 0; y + 1 < n.y; ++y) {
            for (int x = 0; x + 1 < n.x; ++x) {
                auto corner = [&](int bits) { return index(x + (bits & 1), y + (bits >> 1 & 1), z + (bits >> 2 & 1)); };
                for (const auto& axes : kAxes) {
                    const std::array<std::uint64_t, 4> g = {corner(0), corner(axes[0]), corner(axes[0] | axes[1]), corner(7)};
                    std::array<std::uint64_t, 4> in{}, out{};
                    int ins = 0, outs = 0;
                    for (std::uint64_t c : g) (value[c] < 0.0 ? in[ins++] : out[outs++]) = c;
                    if (ins == 0 || outs == 0) continue;
                    glm::dvec3 inside(0.0), outside(0.0);
                    for (int k = 0; k < ins; ++k) inside += point(in[k]) / double(ins);
                    for (int k = 0; k < outs; ++k) outside += point(out[k]) / double(outs);
                    if (ins == 1 || outs == 1) {  // one corner apart: a triangle around it
                        const std::uint64_t lone = ins == 1 ? in[0] : out[0];
                        const auto& rest = ins == 1 ? out : in;
                        emit({vertex(lone, rest[0]), vertex(lone, rest[1]), vertex(lone, rest[2])}, inside, outside);
                    } else {  // two and two: a quad on the four edges between them, as two triangles
                        const std::uint32_t a = vertex(in[0], out[0]), b = vertex(in[0], out[1]);
                        const std::uint32_t c = vertex(in[1], out[1]), d = vertex(in[1], out[0]);
                        emit({a, b, c}, inside, outside);
                        emit({a, c, d}, inside, outside);
                    }
                }
            }
        }
    }
    return TriangleMesh(std::move(v), std::move(f));
}

namespace {

// Signed distances (negative inside) of the mannequin's and the chair's parts (Quilez, "distance functions").
double ellipsoid(glm::dvec3 p, glm::dvec3 centre, glm::dvec3 radii) {  // a bound, exact on the surface
    const double k0 = glm::length((p - centre) / radii), k1 = glm::length((p - centre) / (radii * radii));
    return k1 > 0.0 ? k0 * (k0 - 1.0) / k1 : -std::min({radii.x, radii.y, radii.z});
}
double capsule(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, double radius) {
    const glm::dvec3 pa = p - a, ba = b - a;
    const double h = std::clamp(glm::dot(pa, ba) / glm::dot(ba, ba), 0.0, 1.0);
    return glm::length(pa - ba * h) - radius;
}
double rounded_box(glm::dvec3 p, glm::dvec3 centre, glm::dvec3 half, double rounding) {
    const glm::dvec3 q = glm::abs(p - centre) - (half - rounding);
    return glm::length(glm::max(q, 0.0)) + std::min(std::max({q.x, q.y, q.z}), 0.0) - rounding;
}
// The polynomial smooth minimum: a union whose seams are rounded over about k.
double blend(double a, double b, double k) {
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k * 0.25;
}

}  // namespace

TriangleMesh mannequin() {
    const auto field = [](glm::dvec3 p) {
        double torso = ellipsoid(p, {0.0, 0.98, 0.0}, {0.17, 0.13, 0.12});                // hips
        torso = blend(torso, ellipsoid(p, {0.0, 1.13, 0.0}, {0.13, 0.12, 0.095}), 0.06);   // waist
        torso = blend(torso, ellipsoid(p, {0.0, 1.30, 0.01}, {0.16, 0.13, 0.115}), 0.06);  // chest
        torso = blend(torso, capsule(p, {-0.15, 1.42, 0.0}, {0.15, 1.42, 0.0}, 0.065), 0.05);  // shoulders
        torso = blend(torso, capsule(p, {0.0, 1.42, 0.0}, {0.0, 1.56, 0.0}, 0.05), 0.03);  // neck
        for (const double side : {-1.0, 1.0}) {  // arms hanging at the sides
            torso = blend(torso, capsule(p, {side * 0.2, 1.41, 0.0}, {side * 0.235, 1.02, 0.02}, 0.045), 0.03);
        }
        const double stand = blend(capsule(p, {0.0, 0.03, 0.0}, {0.0, 0.9, 0.0}, 0.018),
                                   ellipsoid(p, {0.0, 0.02, 0.0}, {0.2, 0.02, 0.2}), 0.02);
        return blend(torso, stand, 0.02);
    };
    return isosurface(field, {-0.34, -0.02, -0.24}, {0.34, 1.64, 0.24}, 0.016);
}

TriangleMesh chair() {
    const auto field = [](glm::dvec3 p) {
        const double r = 0.015;
        double d = rounded_box(p, {0.0, 0.45, 0.0}, {0.22, 0.02, 0.22}, r);                    // seat
        d = std::min(d, rounded_box(p, {0.0, 0.72, -0.2}, {0.22, 0.25, 0.02}, r));             // backrest
        for (const double x : {-0.19, 0.19}) {
            for (const double z : {-0.19, 0.19}) {
                d = std::min(d, rounded_box(p, {x, 0.22, z}, {0.02, 0.22, 0.02}, 0.01));       // legs
            }
        }
        return d;
    };
    return isosurface(field, {-0.25, -0.02, -0.25}, {0.25, 1.0, 0.25}, 0.015);
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
