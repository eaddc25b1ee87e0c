// The cloth meshes the project makes (cloth_mesh_shapes.hpp): each is a cloth, its rim lies on the outline it
// stands for (no staircase), and its area is the shape's.
#include "clothsim/cloth_mesh.hpp"
#include "clothsim/cloth_mesh_shapes.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <vector>

using namespace clothsim;

namespace {

double area(const TriangleMesh& m) {
    double a = 0.0;
    for (double v : vertex_areas(m.vertices(), m.triangles())) a += v;
    return a;
}

}  // namespace

TEST_CASE("cloth mesh shapes: the Cusick disc is a cloth whose rings, rim included, lie on their circles", "[cloth_mesh]") {
    for (int rings : {25, 50}) {
        const TriangleMesh disc = cloth_disc(0.15, rings);
        CHECK(cloth_mesh_problem(disc.vertices(), disc.triangles()).empty());
        CHECK(disc.vertices().size() == static_cast<std::size_t>(1 + 3 * rings * (rings + 1)));
        for (int k : {1, rings * 3 / 5, rings}) {  // the support's rim is ring 3/5 of the way out
            for (int i = 1 + 3 * k * (k - 1); i <= 3 * k * (k + 1); ++i) {
                CHECK(glm::length(disc.vertices()[i]) == Approx(0.15 * k / rings).epsilon(1e-12));
            }
        }
        // The inscribed polygon's area: 6k-gons of radius R lose (1 - sin(2 pi / 6k) 6k / 2 pi) of pi R^2.
        const int n = 6 * rings;
        CHECK(area(disc) == Approx(0.5 * n * 0.15 * 0.15 * std::sin(2.0 * std::numbers::pi / n)).epsilon(1e-9));
    }
}

TEST_CASE("cloth mesh shapes: the circle skirt's and the cape's first rows are their waist and collar, on their "
          "curves", "[cloth_mesh]") {
    const TriangleMesh skirt = cloth_annulus(0.275, 0.105, 0.45, 0.025);
    CHECK(cloth_mesh_problem(skirt.vertices(), skirt.triangles()).empty());
    const int waist = annulus_inner_count(0.275, 0.105, 0.025);
    CHECK(waist == 50);
    for (int i = 0; i < waist; ++i) {
        const glm::dvec3 p = skirt.vertices()[i];
        CHECK(std::pow(p.x / 0.275, 2) + std::pow(p.z / 0.105, 2) == Approx(1.0).epsilon(1e-12));
    }
    // The area between the ellipses (a + w)(b + w) pi - a b pi, less what the polygons cut off (under 1%).
    const double ring = std::numbers::pi * ((0.275 + 0.45) * (0.105 + 0.45) - 0.275 * 0.105);
    CHECK(area(skirt) == Approx(ring).epsilon(0.01));
    const TriangleMesh cape = cloth_cone_back(0.30, 0.62, 0.85, 0.025, 200.0);
    CHECK(cloth_mesh_problem(cape.vertices(), cape.triangles()).empty());
    const int collar = cone_back_top_count(0.30, 0.025, 200.0);
    for (int i = 0; i < collar; ++i) {
        const glm::dvec3 p = cape.vertices()[i];
        CHECK(p.y == 0.0);
        CHECK(std::hypot(p.x, p.z) == Approx(0.30).epsilon(1e-12));
        CHECK(p.z < 0.06);  // round the back: 200 degrees centred on -z
    }
    // A cone's lateral area over 200 degrees: (200 / 360) pi (r1 + r2) slant, less the chords' (under 1%).
    const double lateral = 200.0 / 360.0 * std::numbers::pi * (0.30 + 0.62) * std::hypot(0.32, 0.85);
    CHECK(area(cape) == Approx(lateral).epsilon(0.01));
}

TEST_CASE("cloth mesh shapes: the tabard is two panels sewn at the shoulder seam, a cloth with a square neck and "
          "its pattern's area",
          "[cloth_mesh]") {
    const TabardPattern p;
    const TriangleMesh tabard = cloth_tabard(p);
    CHECK(cloth_mesh_problem(tabard.vertices(), tabard.triangles()).empty());
    // Every vertex lies on the pattern's surface: on the yoke's half cylinder, or on a panel's plane.
    const double r = p.yoke_radius;
    int seam = 0;
    for (const glm::dvec3& v : tabard.vertices()) {
        CHECK(std::abs(v.x) <= 0.5 * p.width + 1e-12);
        if (v.y >= -r) {
            CHECK(std::hypot(v.y + r, v.z) == Approx(r).epsilon(1e-12));
        } else {
            CHECK(std::abs(v.z) == r);
        }
        // The shoulder seam, on the straps only: the neck is open there.
        if (v.y == 0.0 && v.z == 0.0) {
            ++seam;
            CHECK(std::abs(v.x) >= p.neck_half_width - 1e-12);
        }
    }
    CHECK(seam == 10);  // 5 points across each strap
    // Two boundary loops, the outline (2 x 0.40 + 2 x 1.45 m) and the neck (2 x 0.18 + 2 x 0.15 m): edges used by
    // one triangle, their lengths the pattern's less what the yoke's chords cut off (under 0.2%).
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (const auto& t : tabard.triangles()) {
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = t[e], b = t[(e + 1) % 3];
            ++uses[{std::min(a, b), std::max(a, b)}];
        }
    }
    double boundary = 0.0;
    std::map<std::uint32_t, std::vector<std::uint32_t>> next;
    for (const auto& [edge, count] : uses) {
        if (count != 1) continue;
        boundary += glm::length(tabard.vertices()[edge.first] - tabard.vertices()[edge.second]);
        next[edge.first].push_back(edge.second);
        next[edge.second].push_back(edge.first);
    }
    int loops = 0;
    std::set<std::uint32_t> seen;
    for (const auto& [start, _] : next) {
        if (seen.count(start)) continue;
        ++loops;
        for (std::uint32_t at = start, from = start; !seen.count(at);) {
            seen.insert(at);
            REQUIRE(next[at].size() == 2);
            const std::uint32_t to = next[at][0] == from ? next[at][1] : next[at][0];
            from = at;
            at = to;
        }
    }
    CHECK(loops == 2);
    const double outline = 2.0 * (p.width + p.front_length + p.back_length);
    const double neck = 2.0 * (2.0 * p.neck_half_width + p.neck_front + p.neck_back);
    CHECK(boundary == Approx(outline + neck).epsilon(0.002));
    CHECK(boundary < outline + neck);
    const double pattern = p.width * (p.front_length + p.back_length) - 2.0 * p.neck_half_width * (p.neck_front + p.neck_back);
    CHECK(area(tabard) == Approx(pattern).epsilon(0.002));
}
