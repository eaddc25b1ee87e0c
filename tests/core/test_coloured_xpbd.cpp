// XPBD's coloured form (coloured_xpbd.hpp) against its exact oracle (the list-order XPBD on the same elements
// listed colour by colour), across thread counts; and the colouring itself: no two elements of a colour share
// a particle, every element is in one colour.
#include "every_kernel.hpp"
#include "integrators/coloured_xpbd.hpp"

#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <set>

using namespace clothsim;

namespace {

// The conforming Cusick disc (1951 vertices) held at its centre, with an anisotropic fabric, wind and the
// cylinder under it, on XPBD's fast path.
Scene disc_on_xpbd() {
    Scene scene = load_scene("cusick");
    scene.pins = PinSpec{PinPreset::None, {}, 0.0f, ClipKind::Rigid};
    apply_override(scene, "cloth.mesh=\"cusick-disc-2k.obj\"");
    apply_override(scene, "pins=[{ vertex = 0, radius = 0.09 }]");  // vertex 0: the disc's centre
    apply_override(scene, "material.stretch=[3000, 1000]");
    apply_override(scene, "material.bending=[2e-5, 1e-5]");
    apply_override(scene, "forces.wind=[1.0, 0.0, 2.0]");
    apply_override(scene, "integration.integrator=\"xpbd\"");
    apply_override(scene, "integration.substeps=20");
    apply_override(scene, "solver.method=\"fast\"");
    return scene;
}

// `topology` with its springs, bends and hinges listed colour by colour (each colour's in list order).
Topology in_colour_order(const Topology& topology, const ColouredXpbd& coloured) {
    Topology t = topology;
    for (std::size_t e = 0; e < t.springs.size(); ++e) t.springs[e] = topology.springs[coloured.springs().order[e]];
    for (std::size_t e = 0; e < t.bends.size(); ++e) t.bends[e] = topology.bends[coloured.bends().order[e]];
    for (std::size_t e = 0; e < t.hinges.size(); ++e) t.hinges[e] = topology.hinges[coloured.hinges().order[e]];
    for (std::size_t e = 0; e < t.membranes.size(); ++e) t.membranes[e] = topology.membranes[coloured.membranes().order[e]];
    return t;
}

bool same_state(const MassSpring& a, const MassSpring& b) {
    return a.state().position == b.state().position && a.state().motion == b.state().motion;
}

}  // namespace

TEST_CASE("coloured XPBD: no two elements of a colour share a particle, and every element is in exactly one colour",
          "[xpbd][coloured]") {
    for (const char* mesh : {"cusick-disc-2k.obj", "circle-skirt.obj", "cape.obj"}) {
        Scene scene = disc_on_xpbd();
        scene.pins = PinSpec{PinPreset::None, {}, 0.0f, ClipKind::Rigid};
        apply_override(scene, std::string("cloth.mesh=\"") + mesh + "\"");
        apply_override(scene, "cloth.membrane=\"triangles\"");
        const MassSpring sim = build_simulation(scene);
        const Topology& t = sim.topology();
        const std::optional<ColouredXpbd> coloured = ColouredXpbd::for_topology(t);
        REQUIRE(coloured);
        auto check = [&](const ColouredXpbd::Colours& colours, std::size_t count, auto particles_of, const char* kind) {
            INFO(mesh << ", " << kind << ": " << colours.count() << " colours");
            REQUIRE(colours.order.size() == count);
            std::vector<std::uint32_t> sorted = colours.order;
            std::sort(sorted.begin(), sorted.end());
            for (std::size_t e = 0; e < count; ++e) REQUIRE(sorted[e] == e);
            for (int c = 0; c < colours.count(); ++c) {
                std::set<std::uint32_t> touched;
                std::size_t touches = 0;
                for (std::uint32_t e = colours.begin[c]; e < colours.begin[c + 1]; ++e) {
                    for (std::uint32_t p : particles_of(colours.order[e])) {
                        touched.insert(p);
                        ++touches;
                    }
                    if (e > colours.begin[c]) CHECK(colours.order[e - 1] < colours.order[e]);  // list order within
                }
                CHECK(touched.size() == touches);
            }
            // Greedy colouring needs at most one colour more than the most elements one element meets.
            CHECK(colours.count() <= 40);
        };
        check(coloured->springs(), t.springs.size(),
              [&](std::uint32_t j) { return std::array<std::uint32_t, 2>{t.springs[j].a, t.springs[j].b}; }, "springs");
        check(coloured->hinges(), t.hinges.size(), [&](std::uint32_t j) { return t.hinges[j].v; }, "hinges");
        CHECK(t.hinges.size() > 0);
        check(coloured->membranes(), t.membranes.size(), [&](std::uint32_t j) { return t.membranes[j].v; }, "membranes");
        CHECK(t.membranes.size() == t.triangles.size());
    }
}

TEST_CASE("coloured XPBD is the list-order XPBD on its elements listed colour by colour, bit for bit, with every "
          "kernel and on 1, 2 and 3 threads, linear and with stretch curves", "[xpbd][coloured]") {
    Scene scene = disc_on_xpbd();
    // Curved, the knots at 0.05% and 0.1% are passed where the disc drapes over the support's rim.
    const bool curved = GENERATE(false, true);
    const bool triangles = GENERATE(false, true);
    INFO((curved ? "curved" : "linear") << (triangles ? ", membrane triangles" : ", springs"));
    if (curved) apply_override(scene, "material.stretch_curve={ u = [[0.0005, 2.0], [0.001, 4.0]], v = [[0.0005, 3.0]] }");
    if (triangles) apply_override(scene, "cloth.membrane=\"triangles\"");
    const MassSpring built = build_simulation(scene);
    REQUIRE(built.topology().mesh);
    REQUIRE(built.topology().membranes.size() == (triangles ? built.topology().triangles.size() : 0));
    const std::optional<ColouredXpbd> coloured = ColouredXpbd::for_topology(built.topology());
    REQUIRE(coloured);
    SimulationSettings textbook = built.settings();
    textbook.solver.method = SolverMethod::Textbook;
    MassSpring oracle(in_colour_order(built.topology(), *coloured), built.state(), textbook);
    // Halfway, the springs and hinges stiffen (a slider dragged): the colours' stored stiffness follows.
    auto stiffen = [](MassSpring& sim) {
        SimulationSettings s = sim.settings();
        s.springs.structural *= 1.5f;
        s.springs.bending *= 3.0f;
        sim.apply(s);
    };
    oracle.run_steps(15);
    stiffen(oracle);
    oracle.run_steps(15);
    REQUIRE(oracle.all_finite());
    test::with_every_kernel([&] {
        for (int threads : test::thread_counts({1, 2, 3})) {
            Scene threaded = scene;
            threaded.settings.solver.threads = threads;
            MassSpring sim = build_simulation(threaded);
            sim.run_steps(15);
            stiffen(sim);
            sim.run_steps(15);
            INFO("the " << FastSolver::kernel_name() << " kernel, " << threads << " threads");
            CHECK(sim.last_step_fast());
            CHECK(sim.solver_threads() == threads);
            CHECK(same_state(sim, oracle));
            // The residual --json and the panel report: the same multipliers, C^2 summed in another order.
            CHECK(sim.last_solver_residual() == Approx(oracle.last_solver_residual()).epsilon(1e-9));
            CHECK(sim.last_solver_residual() > 0.0);
        }
    });
    // The default picks its threads as it goes (team_choice.hpp): the same cloth.
    MassSpring automatic = build_simulation(scene);
    automatic.run_steps(15);
    stiffen(automatic);
    automatic.run_steps(15);
    CHECK(same_state(automatic, oracle));
    // And it is another order than the list's (the test above means something): the list path differs.
    Scene list = scene;
    list.settings.solver.method = SolverMethod::Textbook;
    MassSpring listed = build_simulation(list);
    listed.run_steps(15);
    stiffen(listed);
    listed.run_steps(15);
    CHECK_FALSE(listed.last_step_fast());
    CHECK_FALSE(same_state(listed, oracle));
    // Curved, the curve shows: the same run without it ends elsewhere.
    if (curved) {
        Scene straight = scene;
        apply_override(straight, "material.stretch_curve={}");
        MassSpring linear = build_simulation(straight);
        linear.run_steps(15);
        stiffen(linear);
        linear.run_steps(15);
        CHECK_FALSE(same_state(linear, oracle));
    }
}
