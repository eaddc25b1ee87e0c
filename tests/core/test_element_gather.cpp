// The gather of a mesh cloth's spring and hinge forces on the team (element_gather.hpp) against the list path.
#include "model/element_gather.hpp"
#include "model/gaussian_curvature.hpp"

#include "clothsim/cloth_mesh.hpp"
#include "clothsim/scene.hpp"
#include "every_kernel.hpp"
#include "integrators/fast_solver.hpp"
#include "model/forces.hpp"

#include <catch2/catch.hpp>

#include <random>

using namespace clothsim;

TEST_CASE("element gather: a mesh cloth's spring, hinge, membrane and rim-corner forces on the team equal the list path's bit for "
          "bit, with every kernel the CPU runs, on 1, 2 and 3 threads, linear and with stretch curves", "[element_gather]") {
    // The conforming Cusick disc (1951 vertices), every particle moved at random by up to a tenth of an edge,
    // with an anisotropic fabric; one spring given stiffness 0 and one length 0, as the list path skips them.
    // Curved, the strains of up to 10% pass every knot (the springs then take the scalar loop's hinge sums).
    Scene scene = load_scene("cusick");
    scene.pins = PinSpec{PinPreset::None, {}, 0.0f, ClipKind::Rigid};
    apply_override(scene, "cloth.mesh=\"cusick-disc-2k.obj\"");
    apply_override(scene, "material.stretch=[3000, 1000]");
    apply_override(scene, "material.bending=[2e-5, 1e-5]");
    const bool curved = GENERATE(false, true);
    const bool triangles = GENERATE(false, true);
    INFO((curved ? "curved" : "linear") << (triangles ? ", membrane triangles" : ", springs"));
    if (triangles) apply_override(scene, "cloth.membrane=\"triangles\"");
    if (curved) apply_override(scene, "material.stretch_curve={ u = [[0.002, 2.0], [0.01, 4.0]], v = [[0.002, 3.0], [0.02, 9.0]] }");
    const MassSpring sim = build_simulation(scene);
    Topology topology = sim.topology();
    REQUIRE(topology.mesh);
    REQUIRE(!topology.hinges.empty());
    REQUIRE(has_gaussian_term(topology, sim.settings().springs));  // the flat disc's rim corners (gaussian_curvature.hpp)
    REQUIRE(topology.membranes.size() == (triangles ? topology.triangles.size() : 0));
    if (triangles) {
        for (const Spring& s : topology.springs) REQUIRE(s.weight == 0.0f);  // the edges carry nothing: the gather leaves them out
        topology.membranes[11].area = 0.0f;  // a membrane of no stiffness adds zeros
    }
    topology.springs[5].weight = 0.0f;
    DVec3Array position = sim.state().position;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> jitter(-3e-4, 3e-4);
    for (std::size_t i = 0; i < position.size(); ++i) position.add(i, {jitter(rng), jitter(rng), jitter(rng)});
    position.set(topology.springs[9].b, position.get(topology.springs[9].a));  // a spring of no length
    Vec3Array list;
    list.resize(position.size());
    accumulate_spring_forces(topology, position, sim.settings().springs, list);
    ElementGather gather = ElementGather::for_topology(topology);
    // Each particle's sum starts from the force it holds: gravity here, as in a step.
    Vec3Array start;
    start.resize(position.size());
    for (std::size_t i = 0; i < start.size(); ++i) start.set(i, {0.0f, -9.81f * float(1 + i % 7) * 1e-4f, 0.0f});
    Vec3Array from_start;
    from_start.resize(position.size());
    for (std::size_t i = 0; i < start.size(); ++i) from_start.set(i, start.get(i));
    accumulate_spring_forces(topology, position, sim.settings().springs, from_start);
    test::with_every_kernel([&] {
        for (int threads : {1, 2, 3}) {
            Vec3Array team = start;
            gather_spring_forces(topology, gather, position, sim.settings().springs, team, threads);
            INFO("the " << FastSolver::kernel_name() << " kernel, " << threads << " threads");
            CHECK(team == from_start);
        }
    });
    // Not trivially equal: the forces are there, and curved they are the curve's.
    double largest = 0.0;
    for (std::size_t i = 0; i < list.size(); ++i) largest = std::max(largest, double(std::abs(list.x[i])));
    CHECK(largest > 1e-3);
    SpringSettings linear = sim.settings().springs;
    linear.mesh_curve = {};
    linear.membrane_curve = {};
    Vec3Array straight;
    straight.resize(position.size());
    accumulate_spring_forces(topology, position, linear, straight);
    CHECK((straight == list) == !curved);
}

TEST_CASE("element gather: a live change of an anisotropic fabric reaches the gather's copy of the springs' weights",
          "[element_gather]") {
    // Warp and weft swapped while the cloth runs change every spring's weight (membrane_springs): the gather,
    // which keeps its own copy of them, must step as the list path does, bit for bit.
    Scene scene = load_scene("cusick");
    scene.pins = PinSpec{PinPreset::None, {}, 0.0f, ClipKind::Rigid};
    apply_override(scene, "cloth.mesh=\"cusick-disc-2k.obj\"");
    apply_override(scene, "material.stretch=[3000, 1000]");
    // Steps of a tenth of the scene's, at its substep length: a short run, as the check needs.
    apply_override(scene, "integration.dt=" + std::to_string(scene.settings.integration.dt / 10.0));
    apply_override(scene, "integration.substeps=" + std::to_string((scene.settings.integration.substeps + 9) / 10));
    Scene textbook = scene;
    apply_override(scene, "solver.method=\"fast\"");
    apply_override(textbook, "solver.method=\"textbook\"");
    MassSpring gathered = build_simulation(scene), listed = build_simulation(textbook);
    REQUIRE(gathered.topology().mesh);
    gathered.run_steps(3);
    listed.run_steps(3);
    const std::vector<float> before = [&] {
        std::vector<float> w;
        for (const Spring& s : gathered.topology().springs) w.push_back(s.weight);
        return w;
    }();
    apply_override(scene, "material.stretch=[1000, 3000]");
    apply_override(textbook, "material.stretch=[1000, 3000]");
    apply_fabric(gathered, scene);
    apply_fabric(listed, textbook);
    std::size_t changed = 0;
    for (std::size_t j = 0; j < before.size(); ++j) changed += gathered.topology().springs[j].weight != before[j];
    CHECK(changed > before.size() / 2);
    test::with_every_kernel([&] {
        MassSpring a = gathered, b = listed;
        a.run_steps(5);
        b.run_steps(5);
        INFO("the " << FastSolver::kernel_name() << " kernel");
        CHECK(a.state().position == b.state().position);
    });
}
