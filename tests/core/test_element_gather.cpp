// The gather of a mesh cloth's spring and hinge forces on the team (element_gather.hpp) against the list path.
#include "model/element_gather.hpp"

#include "clothsim/cloth_mesh.hpp"
#include "clothsim/scene.hpp"
#include "model/forces.hpp"

#include <catch2/catch.hpp>

#include <random>

using namespace clothsim;

TEST_CASE("element gather: a mesh cloth's spring and hinge forces on the team equal the list path's bit for bit, "
          "on 1, 2 and 3 threads", "[element_gather]") {
    // The conforming Cusick disc (1951 vertices), every particle moved at random by up to a tenth of an edge,
    // with an anisotropic fabric; one spring given stiffness 0 and one length 0, as the list path skips them.
    Scene scene = load_scene("cusick");
    scene.pins = PinSpec{PinPreset::None, {}, 0.0f, ClipKind::Rigid};
    apply_override(scene, "cloth.mesh=\"cusick-disc-2k.obj\"");
    apply_override(scene, "material.stretch=[3000, 1000]");
    apply_override(scene, "material.bending=[2e-5, 1e-5]");
    const MassSpring sim = build_simulation(scene);
    Topology topology = sim.topology();
    REQUIRE(topology.mesh);
    REQUIRE(!topology.hinges.empty());
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
    for (int threads : {1, 2, 3}) {
        Vec3Array team;
        team.resize(position.size());
        gather_spring_forces(topology, gather, position, sim.settings().springs, team, threads);
        INFO(threads << " threads");
        CHECK(team == list);
    }
    // Not trivially equal: the forces are there.
    double largest = 0.0;
    for (std::size_t i = 0; i < list.size(); ++i) largest = std::max(largest, double(std::abs(list.x[i])));
    CHECK(largest > 1e-3);
}
