// Fuzz target: the OBJ reader of mesh colliders and cloth meshes. Any bytes go to parse_mesh_text(); SceneError
// naming the source is the only allowed failure. An accepted mesh must answer every query a collider asks
// (nearest by the tree and by a contact grid alike, a crossing, a box test, the winding number) with finite
// numbers, at points around and inside its box; and, when cloth_mesh_problem() finds nothing wrong with it as a
// cloth, it must build into a cloth whose every spring weight, hinge weight and mass is finite and positive.
// Built as the other targets (tests/fuzz/CMakeLists.txt).
#include "fuzz_support.hpp"

#include "clothsim/cloth_mesh.hpp"
#include "clothsim/mesh_file.hpp"
#include "clothsim/scene.hpp"

#include <glm/geometric.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace clothsim;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    std::shared_ptr<const TriangleMesh> mesh;
    try {
        fuzz::only_scene_errors("parse_mesh_text", [&] { mesh = parse_mesh_text(text, "fuzz.obj"); });
    } catch (const SceneError& e) {
        if (!std::string_view(e.what()).starts_with("fuzz.obj")) {
            fuzz::fail("a parse_mesh_text() error does not name its source", e.what());
        }
        return 0;
    }
    if (!mesh || mesh->triangles().empty()) fuzz::fail("parse_mesh_text() accepted a mesh without triangles");
    const glm::dvec3 lo = mesh->lo(), hi = mesh->hi(), centre = 0.5 * (lo + hi);
    const double reach = 0.05 * glm::length(hi - lo) + 1e-6;
    const auto grid = mesh->contact_grid(reach);
    for (int k = 0; k < 27; ++k) {
        const glm::dvec3 at(k % 3, (k / 3) % 3, k / 9);
        const glm::dvec3 p = lo + 0.5 * at * (hi - lo) + glm::dvec3(0.3 * reach, -0.2 * reach, 0.1 * reach);
        const auto by_tree = mesh->nearest(p, reach), by_grid = mesh->nearest(p, reach, *grid);
        if (by_tree.has_value() != by_grid.has_value()) fuzz::fail("the contact grid and the tree disagree on a contact");
        if (by_tree && !(by_tree->distance <= reach && std::fabs(by_tree->distance - by_grid->distance) <= 1e-9 * (1.0 + reach))) {
            fuzz::fail("a nearest point out of reach, or the grid's distance differs");
        }
        const auto anywhere = mesh->nearest(p, INFINITY);
        if (!anywhere || !std::isfinite(anywhere->distance)) fuzz::fail("no nearest point at an unbounded radius");
        if (!std::isfinite(mesh->winding_number(p))) fuzz::fail("a winding number that is not finite");
        if (const auto hit = mesh->first_crossing(p, centre + (centre - p), false); hit && !(hit->t >= 0.0 && hit->t <= 1.0)) {
            fuzz::fail("a crossing outside the path");
        }
        (void)mesh->may_touch(p - glm::dvec3(reach), p + glm::dvec3(reach));
    }
    // As a cloth: refused with a reason, or built with finite, positive elements.
    if (!cloth_mesh_problem(mesh->vertices(), mesh->triangles()).empty()) return 0;
    Scene scene;
    scene.cloth.mesh = "fuzz.obj";
    scene.cloth.mesh_data = mesh;
    scene.pins.preset = PinPreset::None;
    scene.material.enabled = true;
    // The builder may still refuse it, with a reason (a mesh too small for its vertices to carry a mass).
    std::optional<MassSpring> built;
    try {
        built.emplace(build_simulation(scene));
    } catch (const SceneError& e) {
        if (!std::string_view(e.what()).starts_with("cloth.mesh")) fuzz::fail("a cloth build error does not name cloth.mesh", e.what());
        return 0;
    }
    const MassSpring& sim = *built;
    for (const Spring& spring : sim.topology().springs) {
        if (!(std::isfinite(spring.weight) && spring.weight >= 0.0f && spring.rest_length > 0.0f)) {
            fuzz::fail("a cloth mesh's spring has a weight or rest length that is not finite and positive");
        }
    }
    for (const Hinge& hinge : sim.topology().hinges) {
        for (float c : hinge.c) {
            if (!std::isfinite(c)) fuzz::fail("a cloth mesh's hinge has a weight that is not finite");
        }
        if (!(std::isfinite(hinge.weight_u) && std::isfinite(hinge.weight_v))) fuzz::fail("a hinge's stiffness is not finite");
    }
    for (float m : sim.state().mass) {
        if (!(std::isfinite(m) && m > 0.0f)) fuzz::fail("a cloth mesh's particle has a mass that is not finite and positive");
    }
    // As constant-strain triangles: one per triangle, with finite weights and a positive area.
    scene.cloth.membrane = MembraneModel::Triangles;
    const MassSpring triangles = build_simulation(scene);  // the same checks passed above
    if (triangles.topology().membranes.size() != triangles.topology().triangles.size()) fuzz::fail("a triangle without its membrane");
    for (const Membrane& m : triangles.topology().membranes) {
        for (int i = 0; i < 3; ++i) {
            if (!(std::isfinite(m.bu[i]) && std::isfinite(m.bv[i]))) fuzz::fail("a membrane triangle's weight is not finite");
        }
        if (!(std::isfinite(m.area) && m.area > 0.0f)) fuzz::fail("a membrane triangle's area is not finite and positive");
    }
    return 0;
}
