// The cloth builder: grid placement along the axes, spring counts and rest lengths per kind, mass, triangles.
#include "support.hpp"

#include "clothsim/material.hpp"
#include "clothsim/stability.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <set>
#include <utility>
#include <vector>

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


namespace {

// The scene with every material field scaled (stretch, shear and bending by `stiffer`, density by `heavier`),
// or in the per-spring form cloth.mass and the springs' k.
Scene fabric_scaled(const Scene& scene, float stiffer, float heavier) {
    Scene s = scene;
    if (s.material.enabled) {
        s.material.stretch *= stiffer;
        s.material.shear *= stiffer;
        s.material.bending *= stiffer;
        s.material.density *= heavier;
        s.material.explicit_fields = kMaterialDensity | kMaterialStretch | kMaterialShear | kMaterialBending;
        derive_springs(s);
    } else {
        s.settings.springs.structural *= stiffer;
        s.settings.springs.shear *= stiffer;
        s.settings.springs.bending *= stiffer;
        s.cloth.mass *= heavier;
    }
    return s;
}

}  // namespace

TEST_CASE("apply_fabric: on every bundled scene, the masses and constants of a cloth built with the new fabric, "
          "positions and velocities kept",
          "[cloth_builder][fabric]") {
    for (const std::string& name : bundled_scene_names()) {
        INFO(name);
        const Scene scene = test::scene_for_loops(name);
        MassSpring sim = build_simulation(scene);
        sim.run_steps(3);
        for (const auto& [stiffer, heavier] : {std::pair{10.0f, 2.0f}, std::pair{0.1f, 0.5f}}) {
            const Scene changed = fabric_scaled(scene, stiffer, heavier);
            const MassSpring built = build_simulation(changed);
            const MassSpring before = sim;
            const std::uint64_t stamp = sim.change_stamp();
            apply_fabric(sim, changed);
            CHECK(test::bit_identical(sim, before));  // positions and motion (x - x_prev): no restart
            CHECK(sim.change_stamp() == stamp);
            CHECK(sim.state().mass == built.state().mass);
            CHECK(std::equal(sim.state().inverse_mass.begin(), sim.state().inverse_mass.end(),
                             built.state().inverse_mass.begin(), built.state().inverse_mass.end()));
            CHECK(sim.settings().springs == built.settings().springs);
            for (std::size_t h = 0; h < sim.topology().clip_springs.size(); ++h) {  // soft clips follow the stiffness
                CHECK(sim.topology().clip_springs[h].stiffness == built.topology().clip_springs[h].stiffness);
            }
            // As the app's auto substeps does: a stiffer fabric needs shorter substeps.
            sim.set_substeps(auto_substeps(stability_limit(sim), sim.settings().integration.dt, 0.5f,
                                           scene.settings.integration.substeps));
            sim.run_steps(2);
            CHECK(sim.all_finite());
        }
    }
}

TEST_CASE("apply_fabric: a hanging cloth stiffened live settles where a cloth built stiff settles", "[cloth_builder][fabric]") {
    // A 12 x 12 cotton-weight sheet hanging from its top corners, stretchy (60 N/m) so that its sag is large,
    // heavily damped (c = 8/s: the slowest swing decays as e^(-4 t)) so that 5 s settle it to 1e-6 m.
    Scene soft = load_scene("hanging");
    soft.cloth.rows = soft.cloth.cols = 12;
    soft.material.stretch = {60.0f, 60.0f};
    soft.material.shear = 6.0f;
    soft.material.explicit_fields |= kMaterialStretch | kMaterialShear;
    soft.settings.springs.damping = 8.0f;
    soft.settings.springs.tether_strain = 0.0f;
    test::collider(soft.settings.colliders, "ground").enabled = false;
    derive_springs(soft);
    const Scene stiff = fabric_scaled(soft, 10.0f, 1.0f);
    // One substep for both, inside the stiff cloth's limit.
    const int substeps = auto_substeps(stability_limit(build_simulation(stiff)), stiff.settings.integration.dt, 0.5f);
    const long long steps = static_cast<long long>(5.0 / stiff.settings.integration.dt);
    auto lowest = [](const MassSpring& s) {
        double y = INFINITY;
        for (std::size_t i = 0; i < s.particle_count(); ++i) y = std::min(y, s.state().position.y[i]);
        return y;
    };
    MassSpring live = build_simulation(soft);
    live.set_substeps(substeps);
    live.run_steps(steps);
    const double soft_low = lowest(live);
    // Stiffened while it hangs: the next substeps move it as continuously as the steps before did.
    double fastest = 0.0;
    for (const glm::vec3& v : live.velocities()) fastest = std::max(fastest, double(glm::length(v)));
    const std::vector<glm::vec3> before = live.positions();
    apply_fabric(live, stiff);
    live.run_steps(1);
    const double step = stiff.settings.integration.dt;
    for (std::size_t i = 0; i < before.size(); ++i) {
        // From rest (|v| < 1e-5 m/s), a step moves a particle by at most about g dt^2 / 2 and what the new
        // springs do in it: far less than a restart, which puts the cloth back at its flat start.
        CHECK(glm::length(live.position(i) - before[i]) <= fastest * step + 10.0 * 9.81 * step * step);
    }
    live.run_steps(steps);
    MassSpring built = build_simulation(stiff);
    built.set_substeps(substeps);
    built.run_steps(2 * steps);
    CHECK(soft_low < lowest(built) - 0.05);  // the soft sheet hangs more than 5 cm lower
    CHECK(lowest(live) == Approx(lowest(built)).margin(1e-5));
}

TEST_CASE("apply_fabric: refuses another grid or another form, changing nothing", "[cloth_builder][fabric]") {
    const Scene scene = load_scene("hanging");
    MassSpring sim = build_simulation(scene);
    sim.run_steps(2);
    const MassSpring copy = sim;
    Scene other_grid = scene;
    other_grid.cloth.rows += 1;
    CHECK_THROWS_WITH(apply_fabric(sim, other_grid), Catch::Contains("rebuild"));
    Scene per_spring = scene;
    per_spring.material = MaterialSettings{};
    CHECK_THROWS_WITH(apply_fabric(sim, per_spring), Catch::Contains("rebuild"));
    Scene too_dense = scene;
    too_dense.material.density = std::nanf("");
    CHECK_THROWS(apply_fabric(sim, too_dense));
    CHECK(test::bit_identical(sim, copy));
    CHECK(sim.state().mass == copy.state().mass);
    CHECK(sim.settings() == copy.settings());
}

TEST_CASE("set_masses: keeps velocities, so the kinetic energy scales with the mass, refuses bad masses", "[fabric]") {
    MassSpring sim = build_simulation(load_scene("falling"));
    sim.run_steps(10);
    const double kinetic = sim.energy().kinetic;
    REQUIRE(kinetic > 0.0);
    std::vector<float> heavier = sim.state().mass;
    for (float& m : heavier) m *= 3.0f;
    sim.set_masses(heavier);
    CHECK(sim.energy().kinetic == Approx(3.0 * kinetic).epsilon(1e-6));
    const std::vector<float> kept = sim.state().mass;
    std::vector<float> bad = kept;
    bad[1] = 0.0f;
    CHECK_THROWS_WITH(sim.set_masses(bad), Catch::Contains("particle 1"));
    bad[1] = std::nanf("");
    CHECK_THROWS(sim.set_masses(bad));
    bad.pop_back();
    CHECK_THROWS_WITH(sim.set_masses(bad), Catch::Contains("masses for"));
    CHECK(sim.state().mass == kept);
}
