// The cloth builder: grid placement along the axes, spring counts and rest lengths per kind, mass, triangles.
#include "support.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <set>

using namespace clothsim;

TEST_CASE("cloth_builder places rows x cols particles along the two axes", "[cloth_builder]") {
    Scene s;
    s.cloth.rows = 4;
    s.cloth.cols = 6;
    s.cloth.size = {2.5f, 1.5f};
    s.cloth.origin = {1.0f, 2.0f, 3.0f};
    s.cloth.u_axis = {0.0f, 0.0f, 2.0f};  // normalised by the builder
    s.cloth.v_axis = {-3.0f, 0.0f, 0.0f};
    const MassSpring sim = build_simulation(s);
    REQUIRE(sim.particle_count() == 24);
    CHECK(sim.position(0) == glm::vec3(1.0f, 2.0f, 3.0f));
    const glm::vec3 last = sim.position(23);  // row 3, col 5
    CHECK(last.x == Approx(1.0f - 1.5f));
    CHECK(last.y == Approx(2.0f));
    CHECK(last.z == Approx(3.0f + 2.5f));
    CHECK(sim.position(s.cloth.cols).x == Approx(1.0f - 0.5f));  // row 1, col 0
    double mass = 0.0;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) mass += sim.particle(i).mass;
    CHECK(mass == Approx(s.cloth.mass));
    CHECK(sim.rest_area() == Approx(2.5f * 1.5f));
}

TEST_CASE("cloth_builder makes structural, shear and bending springs with their rest lengths", "[cloth_builder]") {
    for (auto [rows, cols] : {std::pair{5, 7}, std::pair{1, 9}, std::pair{9, 1}, std::pair{2, 2}, std::pair{1, 1}}) {
        Scene s;
        s.cloth.rows = rows;
        s.cloth.cols = cols;
        s.cloth.size = {1.2f, 0.8f};
        const MassSpring sim = build_simulation(s);
        const Topology& t = sim.topology();
        const auto count = [&](SpringKind k) { return t.spring_count_by_kind[static_cast<int>(k)]; };
        INFO(rows << " x " << cols);
        CHECK(count(SpringKind::Structural) == std::size_t(rows * (cols - 1) + (rows - 1) * cols));
        CHECK(count(SpringKind::Shear) == std::size_t(2 * (rows - 1) * (cols - 1)));
        CHECK(count(SpringKind::Bending) ==
              std::size_t(rows * std::max(cols - 2, 0) + std::max(rows - 2, 0) * cols));
        CHECK(t.springs.size() == count(SpringKind::Structural) + count(SpringKind::Shear) + count(SpringKind::Bending));
        CHECK(t.triangles.size() == std::size_t(2 * (rows - 1) * (cols - 1)));

        const float du = cols > 1 ? 1.2f / float(cols - 1) : 0.0f;
        const float dv = rows > 1 ? 0.8f / float(rows - 1) : 0.0f;
        std::set<std::pair<std::uint32_t, std::uint32_t>> seen;
        for (const Spring& sp : t.springs) {
            CHECK(sp.a != sp.b);
            CHECK(seen.insert({std::min(sp.a, sp.b), std::max(sp.a, sp.b)}).second);  // no duplicates
            const int dr = std::abs(int(sp.a) / cols - int(sp.b) / cols);
            const int dc = std::abs(int(sp.a) % cols - int(sp.b) % cols);
            const float expected = std::sqrt((dc * du) * (dc * du) + (dr * dv) * (dr * dv));
            CHECK(sp.rest_length == Approx(expected));
            CHECK(sp.rest_length == Approx(glm::length(sim.position(sp.a) - sim.position(sp.b))));
            switch (sp.kind) {
                case SpringKind::Structural: CHECK(dr + dc == 1); break;
                case SpringKind::Shear: CHECK((dr == 1 && dc == 1)); break;
                case SpringKind::Bending: CHECK(((dr == 2 && dc == 0) || (dr == 0 && dc == 2))); break;
            }
        }
    }
}

TEST_CASE("cloth_builder winds every triangle with normal u_axis x v_axis", "[cloth_builder]") {
    Scene s;
    s.cloth.rows = 3;
    s.cloth.cols = 4;
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.0f, 0.0f, 1.0f};  // lying flat: normal (1,0,0) x (0,0,1) = (0,-1,0)
    const MassSpring sim = build_simulation(s);
    for (const auto& tri : sim.topology().triangles) {
        const glm::vec3 a = sim.position(tri[0]);
        const glm::vec3 n = glm::normalize(glm::cross(sim.position(tri[1]) - a, sim.position(tri[2]) - a));
        CHECK(n.y == Approx(-1.0f));
    }
}

TEST_CASE("cloth_builder pins and inverse masses", "[cloth_builder]") {
    Scene s;
    s.cloth.rows = 3;
    s.cloth.cols = 3;
    s.pins.preset = PinPreset::TopRow;
    s.pins.particles = {{2, 2}};
    const MassSpring sim = build_simulation(s);
    for (std::size_t i = 0; i < 9; ++i) {
        const bool pinned = i < 3 || i == 8;
        CHECK(sim.particle(i).pinned == pinned);
        CHECK(sim.state().inverse_mass[i] == (pinned ? 0.0f : 1.0f / sim.particle(i).mass));
    }
}

TEST_CASE("cloth_builder rejects what it cannot build with a message", "[cloth_builder]") {
    Scene s;
    s.cloth.u_axis = {0.0f, 1.0f, 0.0f};
    s.cloth.v_axis = {0.0f, -2.0f, 0.0f};
    CHECK_THROWS_WITH(build_simulation(s), Catch::Contains("parallel"));
    s = Scene{};
    s.cloth.rows = 2048;
    s.cloth.cols = 2048;
    CHECK_THROWS_WITH(build_simulation(s), Catch::Contains("too many") && Catch::Contains("1048576"));
    s = Scene{};
    s.cloth.mass = -1.0f;
    CHECK_THROWS_WITH(build_simulation(s), Catch::Contains("cloth.mass"));
    s = Scene{};
    s.pins.particles = {{40, 0}};
    CHECK_THROWS_WITH(build_simulation(s), Catch::Contains("outside the 32 x 32 grid"));
}

TEST_CASE("cloth_builder: a clip pins exactly the particles within its radius at rest", "[cloth_builder][pins]") {
    using V = std::vector<std::size_t>;
    ClothSettings cloth;
    cloth.rows = 5;
    cloth.cols = 5;
    cloth.size = {0.4f, 0.4f};  // spacing 0.1 m both ways; particle [r, c] is index 5 r + c
    auto clip = [&](int r, int c, float radius) {
        return pinned_particles(cloth, {PinPreset::None, {{r, c, radius}}});
    };
    // Around [2, 2] (index 12): the 4 neighbours lie 0.1 m away, the 4 diagonals 0.141 m, the next ring 0.2 m.
    CHECK(clip(2, 2, 0.0f) == V{12});
    CHECK(clip(2, 2, 0.09f) == V{12});
    CHECK(clip(2, 2, 0.1f) == V{7, 11, 12, 13, 17});  // a particle on the rim is held
    CHECK(clip(2, 2, 0.15f) == V{6, 7, 8, 11, 12, 13, 16, 17, 18});
    CHECK(clip(2, 2, 0.2f) == V{2, 6, 7, 8, 10, 11, 12, 13, 14, 16, 17, 18, 22});
    // At a corner the clip is cut by the cloth's edges; a radius larger than the cloth pins all of it.
    CHECK(clip(0, 0, 0.15f) == V{0, 1, 5, 6});
    CHECK(clip(4, 4, 1.0f).size() == 25);

    // Unequal spacing: 0.1 m along u, 0.2 m along v. Within 0.25 m of [0, 0]: (0.1 c)^2 + (0.2 r)^2 <= 0.0625
    // holds for row 0, cols 0-2 and row 1, cols 0-1.
    cloth.size = {0.4f, 0.8f};
    CHECK(clip(0, 0, 0.25f) == V{0, 1, 2, 5, 6});

    // The preset's radius makes each of its pins a clip; explicit pins keep their own radius.
    cloth.size = {0.4f, 0.4f};
    CHECK(pinned_particles(cloth, {PinPreset::TopCorners, {}, 0.1f}) == V{0, 1, 3, 4, 5, 9});
    CHECK(pinned_particles(cloth, {PinPreset::TopCorners, {{4, 2}}, 0.1f}) == V{0, 1, 3, 4, 5, 9, 22});
    CHECK(pinned_particles(cloth, {PinPreset::TopCorners, {{4, 2, 0.1f}}}) == V{0, 4, 17, 21, 22, 23});

    // A clip centred outside the grid is refused like a point pin.
    CHECK_THROWS_WITH(clip(5, 0, 0.5f), Catch::Contains("[5, 0]") && Catch::Contains("5 x 5 grid"));
}

TEST_CASE("cloth_builder: a clip holds the particles within its radius of the built cloth, skewed axes too",
          "[cloth_builder][pins]") {
    // Axes 60 degrees apart: the distance in the cloth's plane is not sqrt((dc du)^2 + (dr dv)^2). Compare
    // every particle's pin with its distance to the clip's centre in the built cloth.
    Scene s;
    s.cloth.rows = 9;
    s.cloth.cols = 11;
    s.cloth.size = {1.0f, 0.8f};
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.5f, -std::sqrt(3.0f) / 2.0f, 0.0f};
    s.pins = {PinPreset::None, {{4, 5, 0.23f}}};
    const MassSpring sim = build_simulation(s);
    const glm::vec3 centre = sim.position(s.cloth.cols * 4 + 5);
    int pinned = 0;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const float distance = glm::length(sim.position(i) - centre);
        INFO("particle " << i << " at " << distance << " m");
        REQUIRE(std::abs(distance - 0.23f) > 1e-4f);  // none on the rim: the comparison is not about rounding
        CHECK(static_cast<bool>(sim.state().pinned[i]) == (distance < 0.23f));
        CHECK((sim.state().inverse_mass[i] == 0.0f) == (distance < 0.23f));
        pinned += sim.state().pinned[i];
    }
    // Spacing 0.1 m both ways: particles a columns and b rows away lie 0.1 sqrt(a^2 + b^2 + a b) m apart,
    // within 0.23 m for 19 (a, b); perpendicular axes would hold 21.
    CHECK(pinned == 19);
}

