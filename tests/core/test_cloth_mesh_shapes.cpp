// The cloth meshes the project makes (cloth_mesh_shapes.hpp): each is a cloth, its rim lies on the outline it
// stands for (no staircase), and its area is the shape's.
#include "clothsim/cloth_mesh.hpp"
#include "clothsim/cloth_mesh_shapes.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <numbers>

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
