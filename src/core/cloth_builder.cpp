// The one cloth builder: a rows x cols grid placed by an origin and two in-plane axes, with structural,
// shear and bending springs whose rest lengths are the initial distances.
#include "clothsim/scene.hpp"

#include <glm/geometric.hpp>

#include <algorithm>

namespace clothsim {
namespace {

Topology grid_topology(int rows, int cols, const DVec3Array& position) {
    Topology t;
    t.rows = rows;
    t.cols = cols;
    auto add = [&](int r0, int c0, int r1, int c1, SpringKind kind) {
        auto inside = [&](int r, int c) { return r >= 0 && r < rows && c >= 0 && c < cols; };
        if (!inside(r0, c0) || !inside(r1, c1)) return;
        const auto a = static_cast<std::uint32_t>(t.index(r0, c0));
        const auto b = static_cast<std::uint32_t>(t.index(r1, c1));
        // The rest length in the spring kernels' arithmetic (float d, float length), so a spring at its start
        // length exerts exactly no force.
        t.springs.push_back({a, b, glm::length(glm::vec3(position.get(b) - position.get(a))), kind});
        ++t.spring_count_by_kind[static_cast<int>(kind)];
    };
    // Grouped by kind and direction: each group is a set of parallel springs (the layout a fast solver
    // sweeps without two springs of a group writing one particle in the same sweep position).
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c, r, c + 1, SpringKind::Structural);
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c, r + 1, c, SpringKind::Structural);
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c, r + 1, c + 1, SpringKind::Shear);
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c + 1, r + 1, c, SpringKind::Shear);
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c, r, c + 2, SpringKind::Bending);
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c, r + 2, c, SpringKind::Bending);

    // Two triangles per cell, wound so their normal is u_axis x v_axis.
    for (int r = 0; r + 1 < rows; ++r) {
        for (int c = 0; c + 1 < cols; ++c) {
            const auto i00 = static_cast<std::uint32_t>(t.index(r, c));
            const auto i01 = static_cast<std::uint32_t>(t.index(r, c + 1));
            const auto i10 = static_cast<std::uint32_t>(t.index(r + 1, c));
            const auto i11 = static_cast<std::uint32_t>(t.index(r + 1, c + 1));
            t.triangles.push_back({i00, i01, i10});
            t.triangles.push_back({i01, i11, i10});
        }
    }
    return t;
}

}  // namespace

std::vector<std::size_t> pinned_particles(const ClothSettings& cloth, const PinSpec& pins) {
    const int rows = cloth.rows, cols = cloth.cols;
    std::vector<std::size_t> out;
    auto pin = [&](int r, int c) {
        if (r < 0 || r >= rows || c < 0 || c >= cols) {
            throw SceneError("pins: particle [" + std::to_string(r) + ", " + std::to_string(c) + "] is outside the " +
                             std::to_string(rows) + " x " + std::to_string(cols) + " grid");
        }
        out.push_back(static_cast<std::size_t>(r) * cols + c);
    };
    switch (pins.preset) {
        case PinPreset::None: break;
        case PinPreset::TopCorners: pin(0, 0); pin(0, cols - 1); break;
        case PinPreset::TopRow: for (int c = 0; c < cols; ++c) pin(0, c); break;
        case PinPreset::FourCorners: pin(0, 0); pin(0, cols - 1); pin(rows - 1, 0); pin(rows - 1, cols - 1); break;
        case PinPreset::LeftEdge: for (int r = 0; r < rows; ++r) pin(r, 0); break;
    }
    for (const auto& [r, c] : pins.particles) pin(r, c);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

MassSpring build_simulation(const Scene& scene) {
    validate(scene);
    const ClothSettings& cloth = scene.cloth;
    const std::size_t n = static_cast<std::size_t>(cloth.rows) * cloth.cols;
    const glm::vec3 u = glm::normalize(cloth.u_axis);
    const glm::vec3 v = glm::normalize(cloth.v_axis);
    // A single row or column has no spacing along that axis.
    const float du = cloth.cols > 1 ? cloth.size.x / static_cast<float>(cloth.cols - 1) : 0.0f;
    const float dv = cloth.rows > 1 ? cloth.size.y / static_cast<float>(cloth.rows - 1) : 0.0f;

    State state;
    state.position.resize(n);
    for (int r = 0; r < cloth.rows; ++r) {
        for (int c = 0; c < cloth.cols; ++c) {
            const glm::vec3 p = cloth.origin + u * (du * static_cast<float>(c)) + v * (dv * static_cast<float>(r));
            state.position.set(static_cast<std::size_t>(r) * cloth.cols + c, glm::dvec3(p));
        }
    }
    const float particle_mass = cloth.mass / static_cast<float>(n);
    state.mass.assign(n, particle_mass);
    state.inverse_mass.assign(n, 1.0f / particle_mass);
    state.pinned.assign(n, 0);
    for (std::size_t i : pinned_particles(cloth, scene.pins)) {
        state.pinned[i] = 1;
        state.inverse_mass[i] = 0.0f;
    }
    std::vector<glm::vec3> velocity(n, cloth.velocity);
    Topology topology = grid_topology(cloth.rows, cloth.cols, state.position);
    return MassSpring(std::move(topology), std::move(state), scene.settings, velocity);
}

}  // namespace clothsim
