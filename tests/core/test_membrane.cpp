// A mesh cloth's constant-strain membrane triangles (membrane.hpp): the tensor, the energy and its gradient,
// rigid motions, the continuum's energy under uniform strain, and the patch test that the edge springs fail.
#include "clothsim/cloth_mesh.hpp"
#include "clothsim/material.hpp"

#include "model/forces.hpp"
#include "model/membrane.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <random>
#include <vector>

using namespace clothsim;

namespace {

using test::irregular_sheet;
using test::positions;
using test::Sheet;

SpringSettings material_springs(glm::vec2 stretch, float shear) {
    SpringSettings s;
    s.structural = stretch;
    s.shear = shear;
    s.bending = glm::vec2(0.0f);
    return s;
}

}  // namespace

TEST_CASE("membrane: the tensor's uniaxial stiffness is material.stretch along u and along v, its shear "
          "material.shear, as the grid's cells", "[membrane]") {
    for (const auto& [su, sv, g] : {std::tuple{1000.0, 1000.0, 100.0}, std::tuple{5000.0, 2000.0, 30.0}, std::tuple{33.0, 69.0, 5.0}}) {
        const MembraneTensor c = membrane_tensor(su, sv, g);
        CHECK(c.c11 - c.c12 * c.c12 / c.c22 == Approx(su).epsilon(1e-12));
        CHECK(c.c22 - c.c12 * c.c12 / c.c11 == Approx(sv).epsilon(1e-12));
        CHECK(c.c12 == g);
        CHECK(c.c66 == g);
    }
}

TEST_CASE("membrane: its forces are its energy's negative gradient, linear and with stretch curves", "[membrane]") {
    const std::vector<glm::dvec3> rest = {{0.0, 0.0, 0.0}, {0.013, 0.001, 0.002}, {0.004, -0.002, 0.011}};
    const std::vector<std::array<std::uint32_t, 3>> tri = {{0, 1, 2}};
    const Membrane m = membrane_triangles(rest, tri, {1.0, 0.0, 0.0})[0];
    SpringSettings springs = material_springs({3000.0f, 1200.0f}, 80.0f);
    const bool curved = GENERATE(false, true);
    if (curved) {
        springs.membrane_curve[0].knots = 1;
        springs.membrane_curve[0].strain[0] = 0.01f;
        springs.membrane_curve[0].gain[0] = 3.0f;
        springs.membrane_curve[1].knots = 1;
        springs.membrane_curve[1].strain[0] = 0.005f;
        springs.membrane_curve[1].gain[0] = 2.0f;
    }
    const MembraneTensor c = membrane_tensor(springs);
    // Stretched by a few percent along both directions, sheared, turned out of the plane.
    std::vector<glm::dvec3> x = {{0.001, 0.0, 0.0}, {0.0145, 0.003, 0.001}, {0.0052, -0.001, 0.0118}};
    DVec3Array at = positions(x);
    glm::dvec3 pu(0.0), pv(0.0);
    REQUIRE(membrane_forces(at, m, c, springs, pu, pv));
    const double eps = 1e-9;
    for (std::size_t i = 0; i < 3; ++i) {
        const glm::dvec3 f = double(m.bu[i]) * pu + double(m.bv[i]) * pv;
        for (int k = 0; k < 3; ++k) {
            DVec3Array plus = at, minus = at;
            glm::dvec3 d(0.0);
            d[k] = eps;
            plus.add(i, d);
            minus.add(i, -d);
            const double gradient = (membrane_energy(plus, m, c, springs) - membrane_energy(minus, m, c, springs)) / (2 * eps);
            INFO((curved ? "curved" : "linear") << ", corner " << i << ", axis " << k);
            CHECK(-gradient == Approx(f[k]).epsilon(1e-5).margin(1e-9));
        }
    }
}

TEST_CASE("membrane: a rigid motion stores nothing and pulls nothing, and a uniform stretch or shear stores the "
          "continuum's energy", "[membrane]") {
    const std::vector<glm::dvec3> rest = {{0.0, 0.0, 0.0}, {0.02, 0.0, 0.003}, {0.006, 0.0, 0.017}};
    const Membrane m = membrane_triangles(rest, {{0, 2, 1}}, {1.0, 0.0, 0.0})[0];
    const SpringSettings springs = material_springs({2000.0f, 900.0f}, 50.0f);
    const MembraneTensor c = membrane_tensor(springs);
    CHECK(double(m.area) == Approx(0.5 * (0.02 * 0.017 - 0.006 * 0.003)).epsilon(1e-6));
    // Turned by 40 degrees about an oblique axis and moved.
    const glm::dvec3 axis = glm::normalize(glm::dvec3(1.0, 2.0, -0.5));
    const double a = 0.7;
    auto turn = [&](glm::dvec3 p) {
        return p * std::cos(a) + glm::cross(axis, p) * std::sin(a) + axis * glm::dot(axis, p) * (1.0 - std::cos(a)) +
               glm::dvec3(0.3, -1.0, 2.0);
    };
    std::vector<glm::dvec3> moved;
    for (const glm::dvec3& p : rest) moved.push_back(turn(p));
    CHECK(membrane_energy(positions(moved), m, c, springs) < 1e-12);
    glm::dvec3 pu(0.0), pv(0.0);
    REQUIRE(membrane_forces(positions(moved), m, c, springs, pu, pv));
    CHECK(glm::length(pu) < 1e-6);
    CHECK(glm::length(pv) < 1e-6);
    // x stretched by 1 + e along u (x) with z held: e_u = e, e_v = 0, gamma = 0: A C11 e^2 / 2.
    const double e = 0.004;
    std::vector<glm::dvec3> stretched;
    for (const glm::dvec3& p : rest) stretched.push_back({p.x * (1.0 + e), p.y, p.z});
    CHECK(membrane_energy(positions(stretched), m, c, springs) == Approx(0.5 * m.area * c.c11 * e * e).epsilon(1e-4));
    // Both at once: the coupling C12 e_u e_v adds.
    std::vector<glm::dvec3> both;
    for (const glm::dvec3& p : rest) both.push_back({p.x * (1.0 + e), p.y, p.z * (1.0 - 0.5 * e)});
    const double expected = m.area * (0.5 * c.c11 * e * e + 0.5 * c.c22 * 0.25 * e * e - c.c12 * 0.5 * e * e);
    CHECK(membrane_energy(positions(both), m, c, springs) == Approx(expected).epsilon(1e-4));
    // A simple shear x += s z: w_u = (1, 0, 0), w_v = (s, 0, 1): gamma = s, e_v = sqrt(1 + s^2) - 1.
    const double s = 0.01;
    std::vector<glm::dvec3> sheared;
    for (const glm::dvec3& p : rest) sheared.push_back({p.x + s * p.z, p.y, p.z});
    const double ev = std::sqrt(1.0 + s * s) - 1.0;
    CHECK(membrane_energy(positions(sheared), m, c, springs) ==
          Approx(m.area * (0.5 * c.c66 * s * s + 0.5 * c.c22 * ev * ev)).epsilon(1e-4));
}

TEST_CASE("membrane: a uniform strain of an irregular triangulation leaves every inner vertex in equilibrium (the "
          "constant-strain patch test), which the edge springs do not", "[membrane]") {
    // 12 x 12 vertices 1 cm apart, jittered by 0.3 spacings, random diagonals; x -> F x with a stretch of 0.5% along
    // u, -0.2% along v and a shear of 0.3%.
    const Sheet sheet = irregular_sheet(12, 12, 0.01, 0.3, 7);
    std::vector<glm::dvec3> strained;
    for (const glm::dvec3& p : sheet.rest) strained.push_back({1.005 * p.x + 0.003 * p.z, p.y, 0.998 * p.z});
    const DVec3Array at = positions(strained);
    const glm::dvec2 stretch(1000.0, 600.0);
    auto largest_inner_force = [&](MembraneModel model) {
        const Topology t = mesh_topology(sheet.rest, sheet.triangles, {1.0, 0.0, 0.0}, stretch, model);
        SpringSettings springs = material_springs(glm::vec2(stretch), 60.0f);
        DVec3Array force;
        force.resize(sheet.rest.size());
        accumulate_spring_forces(t, at, springs, force);
        double inner = 0.0, outer = 0.0;
        for (std::size_t i = 0; i < sheet.rest.size(); ++i) {
            (sheet.inner[i] ? inner : outer) = std::max(sheet.inner[i] ? inner : outer, glm::length(force.get(i)));
        }
        return std::pair{inner, outer};
    };
    const auto [triangles_inner, triangles_outer] = largest_inner_force(MembraneModel::Triangles);
    const auto [springs_inner, springs_outer] = largest_inner_force(MembraneModel::Springs);
    INFO("largest force on an inner vertex: triangles " << triangles_inner << " N (rim " << triangles_outer << "), springs "
                                                        << springs_inner << " N (rim " << springs_outer << ")");
    // The rim carries the stress (its vertices' forces are the boundary traction); inside it cancels.
    CHECK(triangles_outer > 1e-3);
    CHECK(triangles_inner < 1e-4 * triangles_outer);  // the weights in float: a rest strain of order 1e-7
    CHECK(springs_inner > 0.05 * springs_outer);
}
