// The Gaussian-curvature term of a flat mesh cloth's bending (gaussian_curvature.hpp): nothing stored or felt at
// any flat shape, forces that are minus its energy's gradient, the hinges' coupling of the two curvatures taken
// out, a cut's sides joining the rim, and no term on a mesh that is bent at rest.
#include "clothsim/cloth_mesh.hpp"

#include "model/forces.hpp"
#include "model/gaussian_curvature.hpp"
#include "model/tearing.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <random>
#include <vector>

using namespace clothsim;

namespace {

// The material form's topology of `sheet` (stretch and shear set to 0 by `bending_only`), warp along x.
Topology sheet_topology(const test::Sheet& sheet) {
    return mesh_topology(sheet.rest, sheet.triangles, glm::dvec3(1.0, 0.0, 0.0), glm::dvec2(1000.0), MembraneModel::Springs);
}

SpringSettings bending_only(glm::vec2 bending) {
    SpringSettings s;
    s.structural = glm::vec2(0.0f);
    s.shear = 0.0f;
    s.bending = bending;
    return s;
}

// The sheet (in the x-z plane) displaced along y by z(x, z) = 0.5 (a x^2 + b z^2) about its centre.
DVec3Array curved(const test::Sheet& sheet, double a, double b) {
    glm::dvec3 centre(0.0);
    for (const glm::dvec3& p : sheet.rest) centre += p / double(sheet.rest.size());
    DVec3Array out = test::positions(sheet.rest);
    for (std::size_t i = 0; i < sheet.rest.size(); ++i) {
        const glm::dvec3 q = sheet.rest[i] - centre;
        out.add(i, glm::dvec3(0.0, 0.5 * (a * q.x * q.x + b * q.z * q.z), 0.0));
    }
    return out;
}

double area_of(const test::Sheet& sheet) {
    double area = 0.0;
    for (const auto& t : sheet.triangles) {
        area += 0.5 * glm::length(glm::cross(sheet.rest[t[1]] - sheet.rest[t[0]], sheet.rest[t[2]] - sheet.rest[t[0]]));
    }
    return area;
}

}  // namespace

TEST_CASE("gaussian curvature: any flat shape of the cloth stores nothing and feels no force, however distorted "
          "in its plane or turned", "[gaussian_curvature]") {
    const test::Sheet sheet = test::irregular_sheet(10, 12, 0.01, 0.3, 7);
    const Topology t = sheet_topology(sheet);
    const SpringSettings springs = bending_only({1e-3f, 2e-3f});
    const double c = gaussian_coefficient(t.gaussian, springs);
    REQUIRE(has_gaussian_term(t, springs));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> jitter(-0.002, 0.002);
    // Rotated by 40 degrees about a tilted axis, every vertex moved by up to 0.2 spacings in the sheet's plane.
    const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 1.0, -0.5));
    const double angle = 0.7;
    DVec3Array position = test::positions(sheet.rest);
    for (std::size_t i = 0; i < sheet.rest.size(); ++i) {
        const glm::dvec3 p = sheet.rest[i] + glm::dvec3(jitter(rng), 0.0, jitter(rng));
        position.set(i, p * std::cos(angle) + glm::cross(axis, p) * std::sin(angle) + axis * glm::dot(axis, p) * (1.0 - std::cos(angle)));
    }
    const DVec3Array rest = test::positions(sheet.rest);
    for (const DVec3Array* at : std::array<const DVec3Array*, 2>{&rest, &position}) {
        CHECK(std::abs(gaussian_energy(t, *at, springs)) < 1e-12 * std::abs(c));
        DVec3Array force;
        force.resize(sheet.rest.size());
        accumulate_gaussian_forces(t, *at, springs, force);
        double largest = 0.0;
        for (std::size_t i = 0; i < force.size(); ++i) largest = std::max(largest, glm::length(force.get(i)));
        CHECK(largest < 1e-9 * std::abs(c) / 0.01);  // against c / h, one corner's force
    }
}

TEST_CASE("gaussian curvature: its forces are minus the gradient of its energy", "[gaussian_curvature]") {
    const test::Sheet sheet = test::irregular_sheet(6, 7, 0.01, 0.3, 11);
    const Topology t = sheet_topology(sheet);
    const SpringSettings springs = bending_only({1e-3f, 3e-3f});
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> move(-0.001, 0.001);
    DVec3Array position = curved(sheet, 40.0, -25.0);
    for (std::size_t i = 0; i < position.size(); ++i) position.add(i, glm::dvec3(move(rng), move(rng), move(rng)));
    DVec3Array force;
    force.resize(position.size());
    accumulate_gaussian_forces(t, position, springs, force);
    const double step = 1e-7;
    double worst = 0.0, largest = 0.0;
    for (std::size_t i = 0; i < position.size(); ++i) {
        for (int k = 0; k < 3; ++k) {
            DVec3Array plus = position, minus = position;
            glm::dvec3 d(0.0);
            d[k] = step;
            plus.add(i, d);
            minus.add(i, -d);
            const double numeric = -(gaussian_energy(t, plus, springs) - gaussian_energy(t, minus, springs)) / (2.0 * step);
            worst = std::max(worst, std::abs(numeric - force.get(i)[k]));
            largest = std::max(largest, std::abs(numeric));
        }
    }
    INFO("largest force component " << largest << " N, worst difference " << worst << " N");
    REQUIRE(largest > 0.0);
    CHECK(worst < 1e-6 * largest);
}

TEST_CASE("gaussian curvature: with it, the hinges' energy under a uniform curvature no longer couples the two "
          "curvatures (a bending Poisson ratio of 0, the grid's)", "[gaussian_curvature]") {
    // A plate's energy 0.5 A (B_11 a^2 + 2 B_12 a b + B_22 b^2) for z = 0.5 (a x^2 + b z^2): the coupling is
    // E(a, a) - E(a, 0) - E(0, a) = B_12 a^2 A. The hinges alone give B_12 of about -B / 3 on irregular Delaunay
    // triangles, and about +B / 10 on a jittered grid's cells with random diagonals (docs/MESH_CLOTH.md).
    const test::Mesh delaunay = test::delaunay_rectangle(0.01, 0.3, 0.3, 0.2, 2);
    const test::Sheet cells = test::irregular_sheet(31, 31, 0.01, 0.3, 2);
    for (const test::Sheet& sheet : {test::Sheet{delaunay.vertices, delaunay.triangles, {}}, cells}) {
        const Topology with = sheet_topology(sheet);
        Topology without = with;
        without.gaussian = {};
        const double area = area_of(sheet), a = 0.2;  // a 5 m radius over a 0.3 m sheet: slopes under 0.03
        for (const glm::vec2 bending : {glm::vec2(1e-3f), glm::vec2(1e-3f, 4e-3f)}) {
            const SpringSettings springs = bending_only(bending);
            auto coupling = [&](const Topology& t) {
                auto e = [&](double ka, double kb) { return spring_potential_energy(t, curved(sheet, ka, kb), springs); };
                return (e(a, a) - e(a, 0.0) - e(0.0, a)) / (a * a * area);
            };
            auto along = [&](const Topology& t) { return spring_potential_energy(t, curved(sheet, a, 0.0), springs) / (0.5 * a * a * area); };
            const double b12_hinges = coupling(without), b12 = coupling(with), b11 = along(with);
            INFO((sheet.inner.empty() ? "Delaunay" : "grid cells") << ", bending " << bending.x << ", " << bending.y << ": B_11 "
                 << b11 << ", B_12 " << b12_hinges << " (hinges), " << b12 << " (with the term)");
            CHECK(std::abs(b12_hinges) > 0.05 * b11);
            CHECK(std::abs(b12) < 0.01 * std::abs(b12_hinges));
            // The term's weight is the hinges' B_12 itself: the mesh as a whole stores the material's B_11 = bending.x
            // (the hinges' calibration, cloth_mesh.hpp) and no coupling.
            CHECK(b11 == Approx(bending.x).epsilon(0.01));
            // A cylinder's K is 0: the term stores next to nothing (the angle defects of triangles inscribed in a
            // cylinder are not quite 0 on an irregular mesh: under 0.5% of the bending energy here).
            CHECK(along(without) == Approx(b11).epsilon(5e-3));
        }
    }
}

TEST_CASE("gaussian curvature: a cut's sides join the rim, and the cut cloth still stores nothing flat",
          "[gaussian_curvature][tearing]") {
    const test::Sheet sheet = test::irregular_sheet(12, 12, 0.01, 0.3, 4);
    Topology t = sheet_topology(sheet);
    const SpringSettings springs = bending_only({1e-3f, 1e-3f});
    const std::size_t rim = t.gaussian.rim_corners.size();
    // Cut every edge crossing the line x = 0.055 between z = 0.02 and 0.09.
    const std::size_t removed = break_springs(t, [&](const Spring& s) {
        const glm::dvec3 a = sheet.rest[s.a], b = sheet.rest[s.b];
        return (a.x - 0.055) * (b.x - 0.055) < 0.0 && std::min(a.z, b.z) > 0.02 && std::max(a.z, b.z) < 0.09;
    });
    REQUIRE(removed > 0);
    CHECK(t.gaussian.rim_corners.size() > rim);
    CHECK(std::abs(gaussian_energy(t, test::positions(sheet.rest), springs)) < 1e-12 * gaussian_coefficient(t.gaussian, springs));
    // Bent, the cut cloth's term is its own rim's: each side's rim corners count.
    const DVec3Array bowl = curved(sheet, 10.0, 10.0);
    Topology whole = sheet_topology(sheet);
    CHECK(gaussian_energy(t, bowl, springs) != Approx(gaussian_energy(whole, bowl, springs)).epsilon(1e-3));
}

TEST_CASE("gaussian curvature: no term on a mesh bent at rest, where -B_12 K would pull", "[gaussian_curvature]") {
    test::Sheet sheet = test::irregular_sheet(8, 8, 0.01, 0.3, 9);
    for (glm::dvec3& p : sheet.rest) p.y = 0.5 * 20.0 * p.x * p.x;  // a cylinder of radius 5 cm, roughly
    const Topology t = sheet_topology(sheet);
    CHECK(t.gaussian.weight_u == 0.0f);
    CHECK(t.gaussian.weight_v == 0.0f);
    CHECK(t.gaussian.rim_corners.empty());
}
