// Force stages: Hooke's law, wind pressure on triangles (edge-on: none), gusts.
#include "model/forces.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>

using namespace clothsim;

namespace {

State two_particles(glm::vec3 a, glm::vec3 b) {
    State st = test::free_particles({a, b}, 1.0f);
    st.substep = 0.01f;
    return st;
}

// One triangle with corners at the origin, x and y (area 0.5, normal +z).
Topology one_triangle() {
    Topology t;
    t.rows = 1;
    t.cols = 3;
    t.triangles = {{0, 1, 2}};
    return t;
}

State triangle_state() {
    State st = test::free_particles({{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}}, 1.0f);
    st.substep = 0.01f;
    return st;
}

glm::vec3 total(const Vec3Array& f) {
    glm::vec3 sum(0.0f);
    for (std::size_t i = 0; i < f.size(); ++i) sum += f.get(i);
    return sum;
}

}  // namespace

TEST_CASE("forces Hooke spring pulls a stretched spring together with k (|d| - L0)", "[forces]") {
    Topology t;
    t.springs = {{0, 1, 1.0f, SpringKind::Shear}};
    const State st = two_particles({0.0f, 0.0f, 0.0f}, {0.0f, 3.0f, 4.0f});  // |d| = 5
    SpringSettings k{glm::vec2(100.0f), 7.0f, glm::vec2(1.0f), 0.0f};
    Vec3Array f;
    f.resize(2);
    accumulate_spring_forces(t, st.position, k, f);
    // Shear stiffness 7 N/m, stretch 4 m: 28 N along d = (0, 0.6, 0.8).
    CHECK(f.get(0).y == Approx(28.0f * 0.6f));
    CHECK(f.get(0).z == Approx(28.0f * 0.8f));
    CHECK(f.get(1).y == Approx(-28.0f * 0.6f));
    CHECK(total(f) == glm::vec3(0.0f));
    CHECK(spring_potential_energy(t, st.position, k) == Approx(0.5 * 7.0 * 16.0));
    // Compressed: pushes apart.
    const State compressed = two_particles({0.0f, 0.0f, 0.0f}, {0.5f, 0.0f, 0.0f});
    f.resize(2);
    accumulate_spring_forces(t, compressed.position, k, f);
    CHECK(f.get(0).x == Approx(-7.0f * 0.5f));
}

TEST_CASE("forces wind pushes a face-on triangle with drag A w^2 and an edge-on one not at all", "[forces]") {
    const Topology t = one_triangle();
    const State st = triangle_state();
    ForceSettings forces;
    forces.drag = 0.6f;
    forces.wind = {0.0f, 0.0f, 5.0f};  // along the normal
    Vec3Array f;
    f.resize(3);
    accumulate_wind_forces(t, st, forces, 0.5f, f);
    const glm::vec3 sum = total(f);
    CHECK(sum.z == Approx(0.6 * 0.5 * 25.0));
    CHECK(sum.x == 0.0f);
    CHECK(f.get(0).z == Approx(f.get(1).z));  // shared equally by the corners

    forces.wind = {3.0f, -4.0f, 0.0f};  // in the triangle's plane: edge-on
    f.resize(3);
    accumulate_wind_forces(t, st, forces, 0.5f, f);
    CHECK(glm::length(total(f)) == 0.0f);

    // At 60 degrees to the normal the pressure scales with cos^2: (w . n)^2.
    forces.wind = {5.0f * std::sin(1.0471976f), 0.0f, 5.0f * std::cos(1.0471976f)};
    f.resize(3);
    accumulate_wind_forces(t, st, forces, 0.5f, f);
    CHECK(total(f).z == Approx(0.6 * 0.5 * 25.0 * 0.25).epsilon(1e-4));
    CHECK(total(f).x == Approx(0.0f).margin(1e-6));
}

TEST_CASE("forces wind acts on the relative velocity: a sheet moving with the air feels nothing", "[forces]") {
    const Topology t = one_triangle();
    State st = triangle_state();
    for (std::size_t i = 0; i < 3; ++i) st.motion.set(i, {0.0f, 0.0f, 0.05f});  // 5 m/s along z at h = 0.01
    ForceSettings forces;
    forces.wind = {0.0f, 0.0f, 5.0f};
    Vec3Array f;
    f.resize(3);
    accumulate_wind_forces(t, st, forces, 0.5f, f);
    CHECK(glm::length(total(f)) == Approx(0.0f).margin(1e-6));
}

TEST_CASE("forces uniform wind model drags every particle toward the air velocity", "[forces]") {
    const Topology t = one_triangle();
    const State st = triangle_state();
    ForceSettings forces;
    forces.wind_model = WindModel::Uniform;
    forces.wind = {2.0f, 0.0f, 0.0f};  // in the plane: the triangles model would give nothing
    Vec3Array f;
    f.resize(3);
    accumulate_wind_forces(t, st, forces, 0.5f, f);
    CHECK(total(f).x == Approx(0.6 * 0.5 * 4.0));
}

TEST_CASE("forces gusts vary the wind speed within the set fraction and are deterministic", "[forces]") {
    ForceSettings forces;
    forces.wind = {10.0f, 0.0f, 0.0f};
    CHECK(wind_velocity(forces, 3.7) == forces.wind);  // no gusts: constant
    forces.gust_strength = 0.4f;
    forces.gust_frequency = 0.5f;
    float lo = 1e9f, hi = -1e9f;
    for (int i = 0; i < 2000; ++i) {
        const glm::vec3 w = wind_velocity(forces, i * 0.01);
        CHECK(w.y == 0.0f);
        lo = std::min(lo, w.x);
        hi = std::max(hi, w.x);
    }
    CHECK(lo >= 10.0f * (1.0f - 0.4f) - 1e-4f);
    CHECK(hi <= 10.0f * (1.0f + 0.4f) + 1e-4f);
    CHECK(hi - lo > 10.0f * 0.4f);  // it really gusts
    CHECK(wind_velocity(forces, 1.234) == wind_velocity(forces, 1.234));
}
