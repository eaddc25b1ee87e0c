// Fuzz target: the OBJ reader of mesh colliders. Any bytes go to parse_mesh_text(); SceneError naming the
// source is the only allowed failure. An accepted mesh must answer every query a collider asks (nearest by the
// tree and by a contact grid alike, a crossing, a box test, the winding number) with finite numbers, at
// points around and inside its box. Built as the other targets (tests/fuzz/CMakeLists.txt).
#include "fuzz_support.hpp"

#include "clothsim/mesh_file.hpp"

#include <glm/geometric.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
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
    return 0;
}
