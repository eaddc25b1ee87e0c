// The static meshes (src/render/meshes.hpp): closed, wound counter-clockwise seen from outside, with normals
// that agree with the winding, checked by the divergence theorem (the signed volume of a closed surface wound
// outward is the volume it encloses) and by each triangle's own normal.
#include "meshes.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <numbers>

using namespace clothsim;

namespace {

struct Measure {
    double volume = 0.0;  // sum over triangles of a . (b x c) / 6
    double area = 0.0;
};

// Checks the arrays agree and every triangle faces the way its vertices' normals say; returns its measure.
Measure check_mesh(const MeshData& m) {
    REQUIRE(m.normals.size() == m.positions.size());
    REQUIRE(m.uvs.size() == m.positions.size());
    REQUIRE(m.indices.size() % 3 == 0);
    for (std::uint32_t i : m.indices) REQUIRE(i < m.positions.size());
    for (const glm::vec3& n : m.normals) CHECK(glm::length(n) == Approx(1.0f));
    Measure measure;
    int backwards = 0, degenerate = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const glm::dvec3 a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]), c(m.positions[m.indices[t + 2]]);
        const glm::dvec3 cross = glm::cross(b - a, c - a);  // counter-clockwise: points out
        const double twice_area = glm::length(cross);
        degenerate += twice_area < 1e-9;
        for (int k = 0; k < 3; ++k) backwards += glm::dot(cross, glm::dvec3(m.normals[m.indices[t + k]])) <= 0.0;
        measure.volume += glm::dot(a, glm::cross(b, c)) / 6.0;
        measure.area += 0.5 * twice_area;
    }
    CHECK(backwards == 0);
    CHECK(degenerate == 0);
    return measure;
}

}  // namespace

TEST_CASE("meshes the cube is closed, wound outward, volume 1 and area 6") {
    const Measure m = check_mesh(make_cube());
    CHECK(m.volume == Approx(1.0));
    CHECK(m.area == Approx(6.0));
}

TEST_CASE("meshes the cylinder is a closed prism on the unit cylinder: side, two caps, normals outward") {
    for (int slices : {3, 8, 96}) {
        INFO(slices << " slices");
        const MeshData mesh = make_cylinder(slices);
        const Measure m = check_mesh(mesh);
        // A regular N-gon prism of circumradius 1 and height 1: base area N sin(2 pi / N) / 2, perimeter
        // 2 N sin(pi / N). Wound outward and closed, its signed volume is that area (times height 1).
        const double n = slices, pi = std::numbers::pi;
        const double base = 0.5 * n * std::sin(2.0 * pi / n), perimeter = 2.0 * n * std::sin(pi / n);
        CHECK(m.volume == Approx(base));
        CHECK(m.area == Approx(2.0 * base + perimeter));
        // Every vertex lies on the surface: the side's on r = 1 with the radial normal, the caps' on
        // y = +-0.5 with the normal +-y.
        for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
            const glm::vec3 p = mesh.positions[i], normal = mesh.normals[i];
            const float r = std::sqrt(p.x * p.x + p.z * p.z);
            CHECK(std::abs(p.y) == Approx(0.5f));
            if (normal.y == 0.0f) {
                CHECK(r == Approx(1.0f));
                CHECK(glm::length(normal - glm::vec3(p.x, 0.0f, p.z) / r) < 1e-6f);
            } else {
                CHECK(r <= 1.0f + 1e-6f);
                CHECK(normal == glm::vec3(0.0f, p.y > 0.0f ? 1.0f : -1.0f, 0.0f));
            }
        }
    }
    CHECK(make_cylinder(96).positions.size() < 1000);  // small: uploaded once
}
