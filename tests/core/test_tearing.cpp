// Tearing (tearing.hpp): springs beyond springs.tear_strain break, once per step.
#include "split_obj.hpp"
#include "support.hpp"

#include "clothsim/export.hpp"
#include "clothsim/scene.hpp"
#include "model/tearing.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <utility>

using namespace clothsim;

namespace {

bool has_spring(const Topology& t, std::uint32_t a, std::uint32_t b) {
    for (const Spring& s : t.springs) {
        if ((s.a == a && s.b == b) || (s.a == b && s.b == a)) return true;
    }
    return false;
}


}  // namespace

TEST_CASE("tearing: a hanging chain breaks at its top spring, which carries the most weight", "[tearing]") {
    // Ten 10 g particles on 10 N/m springs 0.1 m long under gravity, damped so that no spring overshoots
    // its static strain: spring j from the top holds the 9 - j particles below it, strain (9 - j) m g / (k L):
    // 0.88 at the top, 0.78 next. A tear strain between them breaks the top spring alone.
    Scene s = test::chain(10, 0.1f, 0.01f, 10.0f);
    s.pins.particles = {{0, 0}};
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.springs.damping = 20.0f;
    s.settings.springs.tear_strain = 0.84f;
    s.settings.integration.substeps = 50;
    s.settings.solver.sleep_speed = 0.0f;
    MassSpring sim = build_simulation(s);
    double top_strain_before = 0.0;
    for (int step = 0; step < 600 && sim.broken_springs() == 0; ++step) {
        top_strain_before = glm::length(sim.state().position.get(1) - sim.state().position.get(0)) / 0.1 - 1.0;
        sim.run_steps(1);
    }
    INFO("top spring's strain in the step before the tear: " << top_strain_before);
    REQUIRE(sim.broken_springs() > 0);
    auto structural = [&] { return sim.topology().spring_count_by_kind[static_cast<int>(SpringKind::Structural)]; };
    CHECK(structural() == 8);  // of 9: the top one (the skip-one spring across it, of stiffness 0, goes too)
    CHECK_FALSE(has_spring(sim.topology(), 0, 1));
    CHECK(has_spring(sim.topology(), 1, 2));
    const std::size_t broken = sim.broken_springs();
    const float bottom = sim.position(9).y;
    sim.run_steps(60);  // the rest falls (at up to g / c = 0.49 m/s): nothing else is under tension
    CHECK(sim.broken_springs() == broken);
    CHECK(sim.position(9).y < bottom - 0.3f);
}

TEST_CASE("tearing: momentum is kept and the energy never rises at a tear", "[tearing]") {
    MassSpring sim = test::pulled_apart(SolverMethod::Fast, 8.0f);
    const double e0 = sim.energy().total();
    const glm::vec3 p0 = sim.momentum();
    REQUIRE(glm::length(p0) < 1e-6f);
    double largest_rise = 0.0;
    int tears = 0;
    for (int step = 0; step < 60; ++step) {
        const std::size_t broken = sim.broken_springs();
        const double before = sim.energy().total();
        sim.run_steps(1);
        const double after = sim.energy().total();
        if (sim.broken_springs() > broken) {
            ++tears;
            largest_rise = std::max(largest_rise, after - before);
        }
        CHECK(glm::length(sim.momentum() - p0) < 1e-5f);
    }
    INFO("tears in " << tears << " steps; largest energy change over a tearing step " << largest_rise << " J; start "
                     << e0 << " J");
    REQUIRE(tears > 0);
    CHECK(sim.broken_springs() > 0);
    CHECK(largest_rise <= 1e-4 * e0);  // Verlet's own energy wobble over a step is below this
    CHECK(sim.energy().total() < e0);
    // Torn down the middle: the two halves are separate pieces.
    const std::vector<std::uint32_t> piece = connected_pieces(sim.topology(), sim.particle_count());
    CHECK(piece[0] != piece[11]);
}

TEST_CASE("tearing: the fast solver tears exactly as the textbook solver", "[tearing]") {
    MassSpring fast = test::pulled_apart(SolverMethod::Fast, 8.0f);
    MassSpring textbook = test::pulled_apart(SolverMethod::Textbook, 8.0f);
    for (int step = 0; step < 40; ++step) {
        fast.run_steps(1);
        textbook.run_steps(1);
    }
    REQUIRE(fast.broken_springs() > 0);
    CHECK(fast.plan().path == StepPath::FastVerlet);
    CHECK(fast.broken_springs() == textbook.broken_springs());
    CHECK(test::bit_identical(fast, textbook));
}

TEST_CASE("tearing: no triangle spans a torn spring, in the topology and in the OBJ export of the split surface", "[tearing]") {
    MassSpring sim = test::pulled_apart(SolverMethod::Fast, 8.0f);
    const std::size_t triangles = sim.topology().triangles.size();
    sim.run_steps(40);
    REQUIRE(sim.broken_springs() > 0);
    const Topology& t = sim.topology();
    CHECK(t.triangles.size() < triangles);
    CHECK_FALSE(t.cell_triangles);
    for (const auto& tri : t.triangles) {
        CHECK(has_spring(t, tri[0], tri[1]));
        CHECK(has_spring(t, tri[1], tri[2]));
        CHECK(has_spring(t, tri[2], tri[0]));
    }
    // The export is the split surface (cloth_surface.hpp): its vertices, UVs and triangles.
    test::check_obj_is_the_split_surface(sim);
}

TEST_CASE("tearing: off at tear_strain 0, and the plan says so", "[tearing]") {
    MassSpring sim = test::pulled_apart(SolverMethod::Fast, 8.0f);
    test::edit_settings(sim, [](SimulationSettings& s) { s.springs.tear_strain = 0.0f; });
    CHECK_FALSE(sim.plan().tear);
    sim.run_steps(40);
    CHECK(sim.broken_springs() == 0);
    bool said = false;
    for (const StageStatus& st : describe(sim.plan(), sim.topology(), sim.settings())) {
        if (st.stage == Stage::Tear) said = st.note == "springs.tear_strain is 0" && !st.runs();
    }
    CHECK(said);
}

TEST_CASE("cutting: a stroke across a hanging sheet parts it there, the lower piece falls, the upper still hangs", "[tearing]") {
    Scene s = load_scene("hanging");
    test::collider(s.settings.colliders, "ground").enabled = false;
    s.settings.springs.tether_strain = 0.0f;
    MassSpring sim = build_simulation(s);
    sim.run_steps(30);
    const std::uint64_t stamp = sim.topology_stamp();
    // The cut: every spring with one end above y = c and the other below it (c: halfway down the sheet).
    const int rows = sim.topology().rows, cols = sim.topology().cols;
    const float c = 0.5f * (sim.position(0).y + sim.position(static_cast<std::size_t>(rows - 1) * cols).y);
    const glm::vec3 p0 = sim.momentum();
    const std::size_t broken = sim.cut([&](glm::vec3 a, glm::vec3 b) { return (a.y - c) * (b.y - c) < 0.0f; });
    CHECK(broken > 0);
    CHECK(sim.broken_springs() == broken);
    CHECK(sim.topology_stamp() != stamp);
    CHECK(glm::length(sim.momentum() - p0) < 1e-6f);  // a cut removes forces, not momentum
    for (const Spring& sp : sim.topology().springs) {
        CHECK((sim.position(sp.a).y - c) * (sim.position(sp.b).y - c) >= 0.0f);
    }
    const std::vector<std::uint32_t> piece = connected_pieces(sim.topology(), sim.particle_count());
    const std::size_t top = 0, bottom = static_cast<std::size_t>(rows - 1) * cols;
    CHECK(piece[top] != piece[bottom]);
    // The lower piece's centre of mass falls freely from its velocity at the cut: y'' = g - c y' (c =
    // springs.damping), y(t) = y0 + g t / c + (v0 - g / c)(1 - exp(-c t)) / c; the upper piece's stays
    // where it hung.
    const std::vector<glm::vec3> velocity = sim.velocities();
    auto centre = [&](std::uint32_t label, glm::dvec3* v) {
        glm::dvec3 sum(0.0), momentum(0.0);
        double mass = 0.0;
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            if (piece[i] != label) continue;
            sum += double(sim.state().mass[i]) * sim.state().position.get(i);
            momentum += double(sim.state().mass[i]) * glm::dvec3(velocity[i]);
            mass += sim.state().mass[i];
        }
        if (v) *v = momentum / mass;
        return sum / mass;
    };
    glm::dvec3 v0;
    const glm::dvec3 lower0 = centre(piece[bottom], &v0), upper0 = centre(piece[top], nullptr);
    sim.run_steps(30);  // 0.5 s
    const double t = 0.5, c_ = s.settings.springs.damping, g = s.settings.forces.gravity.y;
    const double expected = lower0.y + g * t / c_ + (v0.y - g / c_) * (1.0 - std::exp(-c_ * t)) / c_;
    CHECK(centre(piece[bottom], nullptr).y == Approx(expected).margin(0.01));
    CHECK(std::abs(centre(piece[top], nullptr).y - upper0.y) < 0.05);
    CHECK(sim.all_finite());
}

TEST_CASE("tearing: a cut through a mesh cloth of membrane triangles takes each cut edge's triangles with it, "
          "and the piece cut off falls free", "[tearing][membrane]") {
    // The Cusick disc as a mesh of constant-strain triangles held at its centre: its edges (weight 0) still measure
    // strain and break, and the triangles across a broken edge go with it, as the drawn surface's do
    // (cloth_surface.hpp).
    Scene s = load_scene("cusick");
    apply_override(s, "pins=[]");
    apply_override(s, "cloth.mesh=\"cusick-disc-2k.obj\"");
    apply_override(s, "cloth.origin=[0, 0.203, 0]");
    apply_override(s, "pins=[{ vertex = 0, radius = 0.09 }]");
    apply_override(s, "cloth.membrane=\"triangles\"");
    MassSpring sim = build_simulation(s);
    REQUIRE(sim.topology().membranes.size() == sim.topology().triangles.size());
    // A stroke across the disc, outside the support, cuts it in two.
    const std::size_t cut = sim.cut([](glm::vec3 a, glm::vec3 b) { return (a.x - 0.1f) * (b.x - 0.1f) < 0.0f; });
    REQUIRE(cut > 0);
    const Topology& t = sim.topology();
    REQUIRE(t.membranes.size() == t.triangles.size());
    for (std::size_t i = 0; i < t.membranes.size(); ++i) CHECK(t.membranes[i].v == t.triangles[i]);
    for (const Membrane& m : t.membranes) {
        for (int i = 0; i < 3; ++i) CHECK(has_spring(t, m.v[i], m.v[(i + 1) % 3]));
    }
    const std::vector<std::uint32_t> piece = connected_pieces(t, sim.particle_count());
    std::size_t outside = 0;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        if (sim.position(i).x > 0.1f) {
            CHECK(piece[i] != piece[0]);
            ++outside;
        }
    }
    REQUIRE(outside > 0);
    // The piece cut off falls free: nothing of the triangles holds it to the pinned rest.
    sim.run_steps(30);
    REQUIRE(sim.all_finite());
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        if (piece[i] != piece[0]) CHECK(sim.position(i).y < 0.203f - 0.1f);  // half a second of fall: over 1 m
    }
}
