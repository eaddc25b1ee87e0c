// Triangle meshes (clothsim/triangle_mesh.hpp, mesh_shapes.hpp): the hierarchy's queries against a brute-force
// oracle over every triangle, the pseudonormal's side against the winding number, and the shapes the project
// makes being closed solids of the right size.
#include "clothsim/mesh_file.hpp"
#include "clothsim/mesh_shapes.hpp"
#include "clothsim/triangle_mesh.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>

using namespace clothsim;

namespace {

double segment_distance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b) {
    const glm::dvec3 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    return glm::length(p - (a + t * ab));
}

// The distance from p to triangle abc another way than the mesh's (Ericson's regions): the foot of the
// perpendicular on the plane when it lies inside (by barycentric coordinates), else the nearest edge.
double triangle_distance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    const glm::dvec3 foot = p - glm::dot(p - a, n) * n;
    const glm::dvec3 v0 = b - a, v1 = c - a, v2 = foot - a;
    const double d00 = glm::dot(v0, v0), d01 = glm::dot(v0, v1), d11 = glm::dot(v1, v1);
    const double d20 = glm::dot(v2, v0), d21 = glm::dot(v2, v1), den = d00 * d11 - d01 * d01;
    const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
    if (v >= 0.0 && w >= 0.0 && v + w <= 1.0) return std::fabs(glm::dot(p - a, n));
    return std::min({segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

double brute_distance(const TriangleMesh& mesh, glm::dvec3 p) {
    double best = INFINITY;
    for (const auto& t : mesh.triangles()) {
        const auto& v = mesh.vertices();
        best = std::min(best, triangle_distance(p, v[t[0]], v[t[1]], v[t[2]]));
    }
    return best;
}

// The first t in [0, 1] where p0 -> p1 meets a triangle's plane inside the triangle (any side).
double brute_crossing(const TriangleMesh& mesh, glm::dvec3 p0, glm::dvec3 p1) {
    double best = INFINITY;
    for (const auto& t : mesh.triangles()) {
        const auto& v = mesh.vertices();
        const glm::dvec3 a = v[t[0]], b = v[t[1]], c = v[t[2]];
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double s0 = glm::dot(p0 - a, n), s1 = glm::dot(p1 - a, n);
        if ((s0 > 0.0) == (s1 > 0.0) || s0 == s1) continue;
        const double at = s0 / (s0 - s1);
        const glm::dvec3 x = p0 + at * (p1 - p0);
        // Inside: the same side of all three edges.
        const double e0 = glm::dot(glm::cross(b - a, x - a), n), e1 = glm::dot(glm::cross(c - b, x - b), n);
        const double e2 = glm::dot(glm::cross(a - c, x - c), n);
        if (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) best = std::min(best, at);
    }
    return best;
}

}  // namespace

TEST_CASE("triangle mesh nearest finds the closest surface point that every triangle tried gives, and its side",
          "[triangle_mesh]") {
    const TriangleMesh mesh = icosphere(0.3, 3);  // 1280 triangles
    REQUIRE(mesh.triangles().size() == 1280);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> coordinate(-0.45, 0.45);
    int inside = 0, found = 0;
    for (int k = 0; k < 1500; ++k) {
        const glm::dvec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
        INFO("point " << p.x << ", " << p.y << ", " << p.z);
        const double exact = brute_distance(mesh, p);
        const auto unbounded = mesh.nearest(p, INFINITY);
        REQUIRE(unbounded);
        CHECK(unbounded->distance == Approx(exact).margin(1e-12));
        CHECK(glm::length(p - unbounded->point) == Approx(unbounded->distance).margin(1e-12));
        // The side by the pseudonormal is the side by the winding number (1 inside, 0 outside).
        const double winding = mesh.winding_number(p);
        CHECK(std::fabs(winding - std::round(winding)) < 1e-9);
        CHECK(unbounded->inside == (winding > 0.5));
        inside += unbounded->inside;
        // Within a radius: found exactly when the surface is that close.
        const auto near = mesh.nearest(p, 0.02);
        CHECK(near.has_value() == (exact <= 0.02));
        if (near) {
            ++found;
            CHECK(near->distance == Approx(exact).margin(1e-12));
        }
    }
    CHECK(inside > 200);  // the sample holds both sides
    CHECK(found > 50);
}

TEST_CASE("triangle mesh first crossing is the first triangle a path meets, and front_only keeps the way in",
          "[triangle_mesh]") {
    const TriangleMesh mesh = icosphere(0.3, 3);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> coordinate(-0.5, 0.5);
    int crossed = 0;
    for (int k = 0; k < 1500; ++k) {
        const glm::dvec3 p0(coordinate(rng), coordinate(rng), coordinate(rng));
        const glm::dvec3 p1(coordinate(rng), coordinate(rng), coordinate(rng));
        INFO("path " << k);
        const double exact = brute_crossing(mesh, p0, p1);
        const auto hit = mesh.first_crossing(p0, p1, false);
        CHECK(hit.has_value() == std::isfinite(exact));
        if (!hit) continue;
        ++crossed;
        CHECK(hit->t == Approx(exact).margin(1e-9));
        // From outside in only: a path that starts inside the sphere never enters it first.
        const bool starts_inside = mesh.winding_number(p0) > 0.5;
        const auto in = mesh.first_crossing(p0, p1, true);
        if (starts_inside) {
            // Its first front-face crossing, if any, comes after it has left.
            if (in) CHECK(in->t > hit->t);
        } else {
            REQUIRE(in);
            CHECK(in->t == Approx(hit->t).margin(1e-12));
            CHECK(glm::dot(in->normal, p1 - p0) < 0.0);
        }
    }
    CHECK(crossed > 300);
}

TEST_CASE("triangle mesh may_touch is true exactly when a leaf's triangles' box meets the box, never missing one",
          "[triangle_mesh]") {
    const TriangleMesh mesh = icosphere(0.3, 4);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> coordinate(-0.5, 0.5), size(0.0, 0.1);
    for (int k = 0; k < 2000; ++k) {
        const glm::dvec3 lo(coordinate(rng), coordinate(rng), coordinate(rng));
        const glm::dvec3 hi = lo + glm::dvec3(size(rng), size(rng), size(rng));
        bool any = false;
        for (const auto& t : mesh.triangles()) {
            glm::dvec3 tlo(INFINITY), thi(-INFINITY);
            for (auto v : t) tlo = glm::min(tlo, mesh.vertices()[v]), thi = glm::max(thi, mesh.vertices()[v]);
            any = any || (tlo.x <= hi.x && thi.x >= lo.x && tlo.y <= hi.y && thi.y >= lo.y && tlo.z <= hi.z && thi.z >= lo.z);
        }
        INFO("box " << k);
        if (any) CHECK(mesh.may_touch(lo, hi));  // conservative: never misses a triangle
    }
    CHECK_FALSE(mesh.may_touch({0.4, 0.4, 0.4}, {0.5, 0.5, 0.5}));
    CHECK_FALSE(mesh.may_touch({-0.05, -0.05, -0.05}, {0.05, 0.05, 0.05}));  // deep inside: no surface there
}

TEST_CASE("triangle mesh the project's shapes are closed solids: winding number 1 inside, 0 outside",
          "[triangle_mesh]") {
    for (int s : {0, 2, 4}) {
        const TriangleMesh sphere = icosphere(0.3, s);
        INFO("icosphere " << s);
        CHECK(sphere.closed());
        CHECK(sphere.triangles().size() == 20u * (1u << (2 * s)));
        CHECK(sphere.winding_number({0.0, 0.0, 0.0}) == Approx(1.0));
        CHECK(sphere.winding_number({0.0, 0.31, 0.0}) == Approx(0.0).margin(1e-12));
        for (const glm::dvec3& v : sphere.vertices()) CHECK(glm::length(v) == Approx(0.3));
    }
    const TriangleMesh box = box_mesh({1.0, 0.2, 0.5});
    CHECK(box.closed());
    CHECK(box.winding_number({0.49, 0.09, 0.24}) == Approx(1.0));
    CHECK(box.winding_number({0.51, 0.0, 0.0}) == Approx(0.0).margin(1e-12));
    const TriangleMesh table = round_table();
    CHECK(table.closed());
    CHECK(table.triangles().size() > 2000);
    CHECK(table.triangles().size() < 50000);
    CHECK(table.winding_number({0.0, 0.4, 0.0}) == Approx(1.0));   // the column
    CHECK(table.winding_number({0.45, 0.74, 0.0}) == Approx(1.0));  // the top, near its rim
    CHECK(table.winding_number({0.3, 0.5, 0.1}) == Approx(0.0).margin(1e-9));  // under the top, beside the column
    CHECK(table.hi().y == Approx(0.76));
    CHECK(table.hi().x == Approx(0.5));
    CHECK(table.lo().y == Approx(0.0));
    // The top's surface is where the rim's profile says: its nearest point from above is 0.76 high.
    const auto top = table.nearest({0.2, 0.9, 0.1}, 1.0);
    REQUIRE(top);
    CHECK(top->point.y == Approx(0.76));
    CHECK(top->normal.y == Approx(1.0));
    CHECK_FALSE(top->inside);
}

TEST_CASE("triangle mesh refuses no triangles, an index out of range and a coordinate that is not a number",
          "[triangle_mesh]") {
    using V = std::vector<glm::dvec3>;
    using T = std::vector<TriangleMesh::Triangle>;
    const V three = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    CHECK_THROWS_WITH(TriangleMesh(three, T{}), Catch::Contains("no triangles"));
    CHECK_THROWS_WITH(TriangleMesh(three, T{{0, 1, 3}}), Catch::Contains("triangle 1 names vertex 4; the mesh has 3"));
    CHECK_THROWS_WITH(TriangleMesh(V{{0, 0, 0}, {1, NAN, 0}, {0, 1, 0}}, T{{0, 1, 2}}),
                      Catch::Contains("vertex 2 has a coordinate that is not a finite number"));
    const TriangleMesh one(three, T{{0, 1, 2}});
    CHECK_FALSE(one.closed());  // a sheet
}

TEST_CASE("triangle mesh contact grid answers as the tree does, and stays bounded for triangles huge beside the band",
          "[triangle_mesh]") {
    const TriangleMesh mesh = icosphere(0.3, 4);
    const auto grid = mesh.contact_grid(0.01);
    CHECK(mesh.contact_grid(0.01) == grid);  // made once per band
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> coordinate(-0.35, 0.35);
    int found = 0;
    for (int k = 0; k < 20000; ++k) {
        const glm::dvec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
        const auto by_tree = mesh.nearest(p, 0.01), by_grid = mesh.nearest(p, 0.01, *grid);
        INFO("point " << k);
        REQUIRE(by_tree.has_value() == by_grid.has_value());
        if (!by_tree) continue;
        ++found;
        CHECK(by_grid->distance == Approx(by_tree->distance).margin(1e-15));
        CHECK(by_grid->inside == by_tree->inside);
    }
    CHECK(found > 500);
    // Two triangles a kilometre across and a band of a micrometre: larger cells, not billions of listings.
    const TriangleMesh huge({{-5e5, 0, -5e5}, {5e5, 0, -5e5}, {5e5, 0, 5e5}, {-5e5, 0, 5e5}}, {{0, 2, 1}, {0, 3, 2}});
    const auto coarse = huge.contact_grid(1e-6);
    CHECK(coarse->triangles.size() <= 16'000'000u);
    const auto on = huge.nearest({1.0, 0.5e-6, 2.0}, 1e-6, *coarse);
    REQUIRE(on);
    CHECK(on->distance == Approx(0.5e-6));
}

TEST_CASE("triangle mesh a needle's nearest point is on it, and the contact grid answers as the tree does",
          "[triangle_mesh]") {
    // The fuzzer's find (tests/fuzz/corpus/mesh/needle-triangle.obj): triangle 4 has two edges of about 2 m and
    // one of 1.4e-22 m, beside zero-area ones. Its face regions' differences cancel to noise and picked a point
    // off it for a cell's centre, so the grid left it out of a cell where the tree found it; it is measured by
    // its edges, within its width of every point of it.
    const TriangleMesh mesh({{0, 0, 5}, {1, 0, 0}, {1, 0, 0}, {1, 4, 0}, {1, 0, 0}, {1, 1, 0}, {1, 0, 0}, {1, 4, 0},
                             {1, 0, 0}, {1, 4, 0}, {1e-22, 0, 0}, {0, 0, 1e-22}, {0, 1, 0}, {0, 1, 2}},
                            {{1, 2, 3}, {5, 6, 7}, {7, 8, 9}, {0, 1, 2}, {11, 10, 13}, {0, 2, 1}});
    const glm::dvec3 lo = mesh.lo(), hi = mesh.hi();
    const double band = 0.05 * glm::length(hi - lo) + 1e-6;
    const auto grid = mesh.contact_grid(band);
    auto to_segment = [](glm::dvec3 p, glm::dvec3 u, glm::dvec3 v) {
        const double t = std::clamp(glm::dot(p - u, v - u) / glm::dot(v - u, v - u), 0.0, 1.0);
        return glm::length(p - (u + t * (v - u)));
    };
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int k = 0; k < 3000; ++k) {
        // The fuzz target's 27 points first, then random ones near the needle.
        const glm::dvec3 p = k < 27 ? lo + 0.5 * glm::dvec3(k % 3, (k / 3) % 3, k / 9) * (hi - lo) + glm::dvec3(0.3, -0.2, 0.1) * band
                                    : glm::dvec3(unit(rng) - 0.5, 1.5 * unit(rng) - 0.25, 2.5 * unit(rng) - 0.25);
        INFO("point " << k << ": " << p.x << ", " << p.y << ", " << p.z);
        const auto by_tree = mesh.nearest(p, band), by_grid = mesh.nearest(p, band, *grid);
        REQUIRE(by_tree.has_value() == by_grid.has_value());
        const double to_needle = std::min(to_segment(p, {0, 0, 1e-22}, {0, 1, 2}), to_segment(p, {1e-22, 0, 0}, {0, 1, 2}));
        const auto anywhere = mesh.nearest(p, INFINITY);
        REQUIRE(anywhere);
        CHECK(anywhere->distance <= to_needle + 1e-12);
    }
}

TEST_CASE("triangle mesh contact grid knows which of its cells that list no triangle lie inside a closed mesh",
          "[triangle_mesh]") {
    // The icosphere's grid at a 1 cm band has cells that list no triangle inside the ball and around it: a point
    // in one is deep inside exactly when its winding number says inside.
    const TriangleMesh ball = icosphere(0.3, 4);
    const auto grid = ball.contact_grid(0.01);
    REQUIRE(grid->inside.size() == grid->start.size() - 1);
    CHECK(grid->deep_inside({0.0, 0.0, 0.0}));
    CHECK_FALSE(grid->deep_inside({0.0, 0.305, 0.0}));  // near the surface: its cell lists triangles
    CHECK_FALSE(grid->deep_inside({0.0, 0.5, 0.0}));    // outside the grid
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> coordinate(-0.3, 0.3);
    int deep = 0, empty_outside = 0;
    for (int k = 0; k < 4000; ++k) {
        const glm::dvec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
        const std::size_t c = grid->cell_of(p);
        REQUIRE(c != ContactGrid::kNone);
        if (grid->start[c + 1] != grid->start[c]) continue;
        const bool inside = ball.winding_number(p) > 0.5;
        INFO("point " << p.x << ", " << p.y << ", " << p.z);
        CHECK(grid->deep_inside(p) == inside);
        deep += inside;
        empty_outside += !inside;
    }
    CHECK(deep > 500);
    CHECK(empty_outside > 100);
    // An open mesh has no inside.
    const TriangleMesh sheet({{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}}, {{0, 2, 1}, {0, 3, 2}});
    CHECK(sheet.contact_grid(0.01)->inside.empty());
}

TEST_CASE("triangle mesh isosurface meshes a signed distance as a closed surface on its zero set", "[triangle_mesh]") {
    // A sphere of radius 0.3 sampled every 2 cm: every vertex on the sphere (a signed distance interpolates
    // exactly along a grid edge up to its curvature), closed, winding number 1 inside and 0 outside.
    const TriangleMesh ball = isosurface([](glm::dvec3 p) { return glm::length(p) - 0.3; }, glm::dvec3(-0.35),
                                         glm::dvec3(0.35), 0.02);
    CHECK(ball.closed());
    double worst = 0.0;
    for (const glm::dvec3& v : ball.vertices()) worst = std::max(worst, std::abs(glm::length(v) - 0.3));
    CHECK(worst < 2e-3);
    CHECK(ball.winding_number({0.0, 0.0, 0.0}) == Approx(1.0));
    CHECK(ball.winding_number({0.0, 0.31, 0.0}) == Approx(0.0).margin(1e-9));
    // Outward: the face normals point away from the centre.
    for (std::size_t t = 0; t < ball.triangles().size(); t += 97) {
        const auto& f = ball.triangles()[t];
        const glm::dvec3 centre = (ball.vertices()[f[0]] + ball.vertices()[f[1]] + ball.vertices()[f[2]]) / 3.0;
        CHECK(glm::dot(ball.face_normals()[t], centre) > 0.0);
    }
}

TEST_CASE("triangle mesh the mannequin and the chair are closed solids standing on the ground, as bundled",
          "[triangle_mesh]") {
    const TriangleMesh form = mannequin(), seat = chair();
    for (const TriangleMesh* m : {&form, &seat}) {
        CHECK(m->closed());
        CHECK(m->triangles().size() > 2000);
        CHECK(m->triangles().size() <= 50000);
        CHECK(m->lo().y == Approx(0.0).margin(2e-3));
    }
    CHECK(form.winding_number({0.0, 1.25, 0.0}) == Approx(1.0));   // the chest
    CHECK(form.winding_number({0.22, 1.2, 0.0}) == Approx(1.0));   // an arm
    CHECK(form.winding_number({0.0, 0.5, 0.0}) == Approx(1.0));    // the pole
    CHECK(form.winding_number({0.1, 0.5, 0.0}) == Approx(0.0).margin(1e-9));  // beside the pole
    CHECK(form.hi().y == Approx(1.61).margin(0.01));
    CHECK(seat.winding_number({0.0, 0.45, 0.0}) == Approx(1.0));   // the seat
    CHECK(seat.winding_number({0.19, 0.2, 0.19}) == Approx(1.0));  // a leg
    CHECK(seat.winding_number({0.0, 0.2, 0.0}) == Approx(0.0).margin(1e-9));  // under the seat
    // The bundled files are these meshes (clothsim-make-meshes wrote them).
    CHECK(read_mesh_file(mesh_directory() / "mannequin.obj")->triangles().size() == form.triangles().size());
    CHECK(read_mesh_file(mesh_directory() / "chair.obj")->triangles().size() == seat.triangles().size());
}
