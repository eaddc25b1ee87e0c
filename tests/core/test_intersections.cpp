// Self-intersections (intersections.hpp): the exact triangle test the self-collision tests and --json use.
#include "support.hpp"

#include "clothsim/intersections.hpp"
#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <limits>
#include <vector>

using namespace clothsim;

namespace {

// Two triangles: 0-1-2 flat in the y = 0 plane, 3-4-5 standing upright through x = 0.2 (z from -0.5 to
// 0.5, y from -0.5 to 0.5), offset along x by `shift`.
std::vector<glm::vec3> crossing_pair(float shift) {
    return {{0.0f, 0.0f, -1.0f}, {1.0f, 0.0f, 1.0f}, {-1.0f, 0.0f, 1.0f},
            {0.2f + shift, -0.5f, -0.5f}, {0.2f + shift, -0.5f, 0.5f}, {0.2f + shift, 0.5f, 0.0f}};
}

Topology two_triangles(std::array<std::uint32_t, 3> a, std::array<std::uint32_t, 3> b) {
    Topology t;
    t.triangles = {a, b};
    return t;
}

}  // namespace

TEST_CASE("intersections: a triangle standing through another is one pair, moved clear of it none", "[intersections]") {
    const Topology t = two_triangles({0, 1, 2}, {3, 4, 5});
    CHECK(intersecting_triangle_pairs(t, crossing_pair(0.0f)) == 1);
    CHECK(intersecting_triangle_pairs(t, crossing_pair(2.0f)) == 0);   // beside it, boxes apart
    std::vector<glm::vec3> above = crossing_pair(0.0f);
    for (int v = 3; v < 6; ++v) above[v].y += 0.6f;  // lifted: its lowest corner 0.1 above the plane
    CHECK(intersecting_triangle_pairs(t, above) == 0);
    // Touching counts: the upright triangle's lowest edge lies in the plane, inside the other.
    std::vector<glm::vec3> touching = crossing_pair(0.0f);
    for (int v = 3; v < 6; ++v) touching[v].y += 0.5f;
    CHECK(triangles_intersect({glm::dvec3(touching[0]), glm::dvec3(touching[1]), glm::dvec3(touching[2])},
                              {glm::dvec3(touching[3]), glm::dvec3(touching[4]), glm::dvec3(touching[5])}));
}

TEST_CASE("intersections: triangles that share a vertex are not counted, and a NaN corner leaves its triangle out",
          "[intersections]") {
    std::vector<glm::vec3> x = crossing_pair(0.0f);
    // 3-5-2 shares vertex 2 with 0-1-2 and also passes through it (its edge 3-5 crosses the plane inside).
    CHECK(triangles_intersect({glm::dvec3(x[0]), glm::dvec3(x[1]), glm::dvec3(x[2])},
                              {glm::dvec3(x[3]), glm::dvec3(x[5]), glm::dvec3(x[2])}));
    CHECK(intersecting_triangle_pairs(two_triangles({0, 1, 2}, {3, 5, 2}), x) == 0);
    x[4] = glm::vec3(std::numeric_limits<float>::quiet_NaN());
    CHECK(intersecting_triangle_pairs(two_triangles({0, 1, 2}, {3, 4, 5}), x) == 0);
}

TEST_CASE("intersections: a flat cloth has none, also tilted, where its float positions are off the plane by rounding",
          "[intersections]") {
    for (const glm::vec3 v_axis : {glm::vec3(0.0f, 0.0f, 1.0f), glm::vec3(0.3f, -0.7f, 0.2f)}) {
        Scene s = load_scene("falling");
        s.cloth.rows = s.cloth.cols = 48;
        s.cloth.v_axis = v_axis;
        const MassSpring sim = build_simulation(s);
        CHECK(intersecting_triangle_pairs(sim.topology(), sim.positions()) == 0);
    }
}

TEST_CASE("intersections: a cloth folded through itself by hand crosses along the fold", "[intersections]") {
    // A 2 x 8 strip of cells along x; columns from 4 on are mirrored back over x = 3 s and pushed down through
    // the first half (a fold that passes through the layer it folds onto). Every cell of the folded half
    // crosses the flat half somewhere; count at least one pair per folded column.
    Scene s = load_scene("falling");
    s.cloth.rows = 3;
    s.cloth.cols = 9;
    s.cloth.size = {0.8f, 0.2f};
    s.cloth.u_axis = glm::vec3(1.0f, 0.0f, 0.0f);
    s.cloth.v_axis = glm::vec3(0.0f, 0.0f, 1.0f);
    const MassSpring sim = build_simulation(s);
    std::vector<glm::vec3> x = sim.positions();
    const float fold_x = x[4].x;
    for (int r = 0; r < 3; ++r) {
        for (int c = 5; c < 9; ++c) {
            glm::vec3& p = x[static_cast<std::size_t>(r * 9 + c)];
            p.x = 2.0f * fold_x - p.x;
            p.y += (r == 1 ? -0.05f : 0.05f);  // the middle row below the flat half, the edges above: it weaves through
        }
    }
    CHECK(intersecting_triangle_pairs(sim.topology(), x) >= 4);
    CHECK(intersecting_triangle_pairs(sim.topology(), sim.positions()) == 0);
}
