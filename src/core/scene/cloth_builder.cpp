// The one cloth builder: a rows x cols grid placed by an origin and two in-plane axes, with structural,
// shear and bending springs (or bends, with [material]) whose rest lengths are the initial distances.
#include "clothsim/scene.hpp"

#include "scene/cloth_shape.hpp"
#include "clothsim/cloth_mesh.hpp"
#include "clothsim/material.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace clothsim {
namespace {

// Springs by kind and direction, and in the material form bends instead of skip-one bending springs. In the
// material form each element's weight is its share of the cells it borders (material.hpp): a structural
// spring or a bend on the cloth's edge borders one cell row instead of two and carries half. Only particles
// and cells of the shape take part (cloth_shape.hpp).
Topology grid_topology(const ShapeMask& shape, const DVec3Array& position, bool material) {
    const int rows = shape.rows, cols = shape.cols;
    Topology t;
    t.rows = rows;
    t.cols = cols;
    auto add = [&](int r0, int c0, int r1, int c1, SpringKind kind, Axis axis, float weight) {
        if (!shape.has_particle(r0, c0) || !shape.has_particle(r1, c1) || weight == 0.0f) return;
        const auto a = static_cast<std::uint32_t>(t.index(r0, c0));
        const auto b = static_cast<std::uint32_t>(t.index(r1, c1));
        // The rest length in the spring kernels' arithmetic (float d, float length), so a spring at its start
        // length exerts exactly no force.
        t.springs.push_back({a, b, glm::length(glm::vec3(position.get(b) - position.get(a))), kind, axis, 0, weight});
        ++t.spring_count_by_kind[static_cast<int>(kind)];
    };
    auto add_bend = [&](int r0, int c0, int dr, int dc, Axis axis, float weight) {
        const int r1 = r0 + dr, c1 = c0 + dc, r2 = r0 + 2 * dr, c2 = c0 + 2 * dc;
        if (!shape.has_particle(r0, c0) || !shape.has_particle(r1, c1) || !shape.has_particle(r2, c2) ||
            weight == 0.0f) {
            return;
        }
        t.bends.push_back({static_cast<std::uint32_t>(t.index(r0, c0)), static_cast<std::uint32_t>(t.index(r1, c1)),
                           static_cast<std::uint32_t>(t.index(r2, c2)), axis, weight});
        ++t.spring_count_by_kind[static_cast<int>(SpringKind::Bending)];
    };
    auto cell = [&](int r, int c) { return shape.has_cell(r, c) ? 1.0f : 0.0f; };
    // The weights of the material form: half per bordering cell (row of cells, for a bend); 1 otherwise.
    auto along_u = [&](int r, int c) { return material ? 0.5f * (cell(r - 1, c) + cell(r, c)) : 1.0f; };
    auto along_v = [&](int r, int c) { return material ? 0.5f * (cell(r, c - 1) + cell(r, c)) : 1.0f; };
    auto diagonal = [&](int r, int c) { return material ? cell(r, c) : 1.0f; };
    auto bend_u = [&](int r, int c) {
        return 0.5f * (cell(r - 1, c) * cell(r - 1, c + 1) + cell(r, c) * cell(r, c + 1));
    };
    auto bend_v = [&](int r, int c) {
        return 0.5f * (cell(r, c - 1) * cell(r + 1, c - 1) + cell(r, c) * cell(r + 1, c));
    };
    // Grouped by kind and direction: each group is a set of parallel springs (the layout a fast solver
    // sweeps without two springs of a group writing one particle in the same sweep position).
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c, r, c + 1, SpringKind::Structural, Axis::U, along_u(r, c));
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c, r + 1, c, SpringKind::Structural, Axis::V, along_v(r, c));
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c, r + 1, c + 1, SpringKind::Shear, Axis::Diagonal, diagonal(r, c));
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) add(r, c + 1, r + 1, c, SpringKind::Shear, Axis::Diagonal, diagonal(r, c));
    if (material) {
        for (int r = 0; r < rows; ++r)
            for (int c = 0; c < cols; ++c) add_bend(r, c, 0, 1, Axis::U, bend_u(r, c));
        for (int r = 0; r < rows; ++r)
            for (int c = 0; c < cols; ++c) add_bend(r, c, 1, 0, Axis::V, bend_v(r, c));
    } else {
        for (int r = 0; r < rows; ++r)
            for (int c = 0; c < cols; ++c) add(r, c, r, c + 2, SpringKind::Bending, Axis::U, shape.has_particle(r, c + 1));
        for (int r = 0; r < rows; ++r)
            for (int c = 0; c < cols; ++c) add(r, c, r + 2, c, SpringKind::Bending, Axis::V, shape.has_particle(r + 1, c));
    }

    // Two triangles per cell of the shape, wound so their normal is u_axis x v_axis.
    for (int r = 0; r + 1 < rows; ++r) {
        for (int c = 0; c + 1 < cols; ++c) {
            if (!shape.has_cell(r, c)) continue;
            const auto i00 = static_cast<std::uint32_t>(t.index(r, c));
            const auto i01 = static_cast<std::uint32_t>(t.index(r, c + 1));
            const auto i10 = static_cast<std::uint32_t>(t.index(r + 1, c));
            const auto i11 = static_cast<std::uint32_t>(t.index(r + 1, c + 1));
            t.triangles.push_back({i00, i01, i10});
            t.triangles.push_back({i01, i11, i10});
        }
    }
    t.cell_triangles = rows > 1 && cols > 1 &&
                       t.triangles.size() == 2 * static_cast<std::size_t>(rows - 1) * static_cast<std::size_t>(cols - 1);
    return t;
}

// Every particle a pin of `pins` holds: visit(index, radius, distance), the distance at rest from the pin's
// own particle (0 and 0 for a point pin).
// A mesh cloth's pins: each names a vertex; a clip holds every vertex within its radius at rest.
template <class Visit>
void for_each_pinned_vertex(const ClothSettings& cloth, const PinSpec& pins, Visit&& visit) {
    if (pins.preset != PinPreset::None) {
        throw SceneError("pins: the preset \"" + std::string(pin_preset_names()[static_cast<int>(pins.preset)]) +
                         "\" names places on a grid; a mesh cloth (cloth.mesh) is pinned by vertex: allowed: "
                         "pins = [{ vertex = i }, ...] (i counted from 0), or pins = \"none\"");
    }
    const std::vector<glm::dvec3> rest = placed_cloth_vertices(cloth);
    for (const Pin& p : pins.particles) {
        if (p.vertex < 0) {
            throw SceneError("pins: [" + std::to_string(p.row) + ", " + std::to_string(p.col) +
                             "] names a grid particle; a mesh cloth (cloth.mesh) is pinned by vertex: allowed: "
                             "{ vertex = i } or { vertex = i, radius = R }");
        }
        if (static_cast<std::size_t>(p.vertex) >= rest.size()) {
            throw SceneError("pins: vertex " + std::to_string(p.vertex) + " is not a vertex of " + cloth.mesh +
                             "; allowed: a vertex in [0, " + std::to_string(rest.size() - 1) + "]");
        }
        if (!(p.radius > 0.0f)) {
            visit(static_cast<std::size_t>(p.vertex), 0.0, 0.0);
            continue;
        }
        const double reach = double(p.radius) * (1.0 + 1e-6);  // the rim counts, as on the grid
        const glm::dvec3 centre = rest[static_cast<std::size_t>(p.vertex)];
        for (std::size_t i = 0; i < rest.size(); ++i) {
            const double d = glm::length(rest[i] - centre);
            if (d <= reach) visit(i, double(p.radius), d);
        }
    }
}

template <class Visit>
void for_each_pinned(const ClothSettings& cloth, const PinSpec& pins, Visit&& visit) {
    if (cloth.is_mesh()) {
        for_each_pinned_vertex(cloth, pins, visit);
        return;
    }
    const int rows = cloth.rows, cols = cloth.cols;
    // A clip holds the particles within its radius at rest. Rest positions are build_simulation's:
    // origin + c du u + r dv v, u and v normalised, so particles dc columns and dr rows apart lie
    // |dc du u + dr dv v| apart in the cloth's plane, whose square is (dc du)^2 + (dr dv)^2 + 2 dc du dr dv (u . v)
    // (exact for axes that are not perpendicular too).
    const double du = cols > 1 ? double(cloth.size.x) / (cols - 1) : 0.0;
    const double dv = rows > 1 ? double(cloth.size.y) / (rows - 1) : 0.0;
    const glm::dvec3 u = glm::normalize(glm::dvec3(cloth.u_axis)), v = glm::normalize(glm::dvec3(cloth.v_axis));
    const double cos_uv = glm::dot(u, v);
    // A particle dc columns away is at least |dc| du sin(angle) from the clip's centre (its distance to the
    // line through the centre along v), so only a box of rows and columns needs looking at.
    const double sin_uv = std::sqrt(std::max(0.0, 1.0 - cos_uv * cos_uv));
    auto pin = [&](int r, int c, double radius) {
        if (r < 0 || r >= rows || c < 0 || c >= cols) {
            throw SceneError("pins: particle [" + std::to_string(r) + ", " + std::to_string(c) + "] is outside the " +
                             std::to_string(rows) + " x " + std::to_string(cols) + " grid");
        }
        if (!(radius > 0.0)) {  // a point pin
            visit(static_cast<std::size_t>(r) * cols + c, 0.0, 0.0);
            return;
        }
        // A particle on the clip's rim counts: the radius is widened by 1e-6 of itself, far below any grid
        // spacing, so a radius written as exactly k spacings (0.02 m at 0.01 m spacing) is not lost to rounding.
        const double reach = radius * (1.0 + 1e-6);
        auto span = [&](double spacing, int count) {
            return spacing > 0.0 ? static_cast<int>(std::min<double>(count, std::floor(reach / (spacing * sin_uv))))
                                 : 0;
        };
        const int dc_max = span(du, cols), dr_max = span(dv, rows);
        for (int rr = std::max(0, r - dr_max); rr <= std::min(rows - 1, r + dr_max); ++rr) {
            for (int cc = std::max(0, c - dc_max); cc <= std::min(cols - 1, c + dc_max); ++cc) {
                const double a = (cc - c) * du, b = (rr - r) * dv;
                const double distance2 = a * a + b * b + 2.0 * a * b * cos_uv;
                if (distance2 <= reach * reach) {
                    visit(static_cast<std::size_t>(rr) * cols + cc, radius, std::sqrt(std::max(0.0, distance2)));
                }
            }
        }
    };
    const double clip = pins.preset_radius;
    switch (pins.preset) {
        case PinPreset::None: break;
        case PinPreset::TopCorners: pin(0, 0, clip); pin(0, cols - 1, clip); break;
        case PinPreset::TopRow: for (int c = 0; c < cols; ++c) pin(0, c, clip); break;
        case PinPreset::FourCorners:
            pin(0, 0, clip); pin(0, cols - 1, clip); pin(rows - 1, 0, clip); pin(rows - 1, cols - 1, clip);
            break;
        case PinPreset::LeftEdge: for (int r = 0; r < rows; ++r) pin(r, 0, clip); break;
        case PinPreset::Center: pin((rows - 1) / 2, (cols - 1) / 2, clip); break;
    }
    // A grid's vertices are its particles, row-major.
    for (const Pin& p : pins.particles) {
        if (p.vertex >= 0 && cols > 0) {
            pin(p.vertex / cols, p.vertex % cols, p.radius);
        } else {
            pin(p.row, p.col, p.radius);
        }
    }
}

}  // namespace

std::vector<std::size_t> pinned_particles(const ClothSettings& cloth, const PinSpec& pins) {
    std::vector<std::size_t> out;
    for_each_pinned(cloth, pins, [&](std::size_t i, double radius, double) {
        if (radius == 0.0 || pins.clip == ClipKind::Rigid) out.push_back(i);
    });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

std::vector<ClipWeight> soft_clip_weights(const ClothSettings& cloth, const PinSpec& pins) {
    std::vector<ClipWeight> out;
    if (pins.clip != ClipKind::Soft) return out;
    for_each_pinned(cloth, pins, [&](std::size_t i, double radius, double distance) {
        const double t = radius > 0.0 ? distance / radius : 1.0;
        if (t >= 1.0 - 1e-6) return;  // a point pin (rigid), or a particle on the rim: weight 0
        out.push_back({i, (1.0 - t * t) * (1.0 - t * t), radius});
    });
    // A particle in several clips: the one that holds it hardest.
    std::sort(out.begin(), out.end(), [](const ClipWeight& a, const ClipWeight& b) {
        return a.particle != b.particle ? a.particle < b.particle : a.weight / (a.radius * a.radius) > b.weight / (b.radius * b.radius);
    });
    out.erase(std::unique(out.begin(), out.end(), [](const ClipWeight& a, const ClipWeight& b) { return a.particle == b.particle; }),
              out.end());
    return out;
}

std::vector<float> particle_masses(const Scene& scene, const ShapeMask& shape) {
    const ClothSettings& cloth = scene.cloth;
    const std::size_t n = static_cast<std::size_t>(cloth.rows) * cloth.cols;
    std::vector<float> mass(n, 0.0f);
    if (scene.material.enabled) {
        // Each cell's mass density x h_u x h_v goes a quarter to each corner (material.hpp).
        const glm::dvec2 h = grid_spacing(cloth);
        const double quarter = 0.25 * double(scene.material.density) * h.x * h.y;
        for (int r = 0; r < cloth.rows; ++r) {
            for (int c = 0; c < cloth.cols; ++c) {
                const int cells = shape.has_cell(r - 1, c - 1) + shape.has_cell(r - 1, c) + shape.has_cell(r, c - 1) +
                                  shape.has_cell(r, c);
                mass[static_cast<std::size_t>(r) * cloth.cols + c] = static_cast<float>(quarter * cells);
            }
        }
    } else {
        // The total shared equally by the particles of the shape.
        const float share = cloth.mass / static_cast<float>(shape.particle_count);
        for (std::size_t i = 0; i < n; ++i) mass[i] = shape.particle[i] ? share : 0.0f;
    }
    return mass;
}

void apply_fabric(MassSpring& sim, const Scene& scene) {
    const Topology& topology = sim.topology();
    if (topology.mesh || scene.cloth.is_mesh()) {
        const std::size_t n = scene.cloth.mesh_data ? scene.cloth.mesh_data->vertices().size() : 0;
        if (!topology.mesh || !scene.cloth.is_mesh() || n != sim.particle_count()) {
            throw SceneError("the fabric of another cloth cannot be put on the running one: rebuild it");
        }
        // The mesh's weights hold its geometry in the form it was built in (material or per spring).
        if (topology.material_weights != scene.material.enabled) {
            throw SceneError(std::string("switching a mesh cloth between [material] and per-spring values changes its "
                                         "springs' and hinges' weights: rebuild the cloth"));
        }
        const bool triangles = scene.material.enabled && scene.cloth.membrane == MembraneModel::Triangles;
        if (triangles == topology.membranes.empty()) {
            throw SceneError("switching cloth.membrane between springs and triangles changes the cloth's elements: rebuild it");
        }
        if (const std::string clash = material_clash(scene); !clash.empty()) throw SceneError(clash);
        Scene derived = scene;
        derive_springs(derived);
        SimulationSettings settings = sim.settings();
        settings.springs.structural = derived.settings.springs.structural;
        settings.springs.shear = derived.settings.springs.shear;
        settings.springs.bending = derived.settings.springs.bending;
        const std::vector<glm::dvec3> rest = placed_cloth_vertices(derived.cloth);
        if (scene.material.enabled && !triangles) {  // the triangles' stiffness is the settings' (membrane.hpp)
            sim.set_spring_weights(membrane_springs(rest, derived.cloth.mesh_data->triangles(), glm::dvec3(derived.cloth.u_axis),
                                                    glm::dvec2(derived.material.stretch)));
        }
        sim.set_masses(mesh_cloth_masses(derived.cloth, vertex_areas(rest, derived.cloth.mesh_data->triangles())));
        sim.apply(settings);
        return;
    }
    if (topology.rows != scene.cloth.rows || topology.cols != scene.cloth.cols) {
        throw SceneError("the fabric of a " + std::to_string(scene.cloth.rows) + " x " +
                         std::to_string(scene.cloth.cols) + " cloth cannot be put on the running " +
                         std::to_string(topology.rows) + " x " + std::to_string(topology.cols) + " one: rebuild it");
    }
    // The material form has bends where the per-spring form has skip-one springs: another topology.
    const std::size_t skip_one = topology.spring_count_by_kind[int(SpringKind::Bending)] - topology.bends.size();
    if (scene.material.enabled ? skip_one > 0 : !topology.bends.empty()) {
        throw SceneError(std::string("switching between [material] and per-spring values changes the bending "
                                     "elements (bends or skip-one springs): rebuild the cloth"));
    }
    if (const std::string clash = material_clash(scene); !clash.empty()) throw SceneError(clash);
    Scene derived = scene;
    derive_springs(derived);  // throws for a grid [material] cannot fill
    SimulationSettings settings = sim.settings();
    settings.springs.structural = derived.settings.springs.structural;
    settings.springs.shear = derived.settings.springs.shear;
    settings.springs.bending = derived.settings.springs.bending;
    sim.set_masses(particle_masses(derived, shape_mask(derived.cloth)));
    sim.apply(settings);
}

void validate_mesh_cloth(const Scene& scene) {
    const ClothSettings& cloth = scene.cloth;
    if (!cloth.mesh_data) {
        throw SceneError("cloth.mesh = \"" + cloth.mesh + "\" holds no mesh; allowed: a Wavefront OBJ file that loads");
    }
    if (cloth.mesh_data->vertices().size() > static_cast<std::size_t>(kMaxParticles)) {
        throw SceneError("cloth.mesh = \"" + cloth.mesh + "\" has " + std::to_string(cloth.mesh_data->vertices().size()) +
                         " vertices, too many particles; allowed: at most " + std::to_string(kMaxParticles));
    }
    pinned_particles(cloth, scene.pins);  // throws for a pin that names no vertex
}

namespace {

// A mesh cloth (cloth_mesh.hpp): particles at the placed vertices, the mesh model's springs and hinges.
MassSpring build_mesh_simulation(const Scene& scene) {
    const ClothSettings& cloth = scene.cloth;
    const std::vector<glm::dvec3> rest = placed_cloth_vertices(cloth);
    const auto& triangles = cloth.mesh_data->triangles();
    const std::size_t n = rest.size();
    State state;
    state.position.resize(n);
    for (std::size_t i = 0; i < n; ++i) state.position.set(i, rest[i]);
    Scene derived = scene;
    derive_springs(derived);
    const std::vector<double> area = vertex_areas(rest, triangles);
    state.mass = mesh_cloth_masses(derived.cloth, area);
    state.inverse_mass.resize(n);
    state.pinned.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) state.inverse_mass[i] = 1.0f / state.mass[i];
    for (std::size_t i : pinned_particles(cloth, scene.pins)) {
        state.pinned[i] = kPinned;
        state.inverse_mass[i] = 0.0f;
    }
    Topology topology = mesh_topology(rest, triangles, glm::dvec3(cloth.u_axis),
                                      scene.material.enabled ? std::optional(glm::dvec2(derived.material.stretch)) : std::nullopt,
                                      scene.material.enabled ? cloth.membrane : MembraneModel::Springs);
    // Soft clips as on the grid: k = kappa A w, kappa = kClipHoldFactor E / R^2, A the vertex's area, E the
    // springs' stretch along u and v (springs.structural on a mesh).
    for (const ClipWeight& w : soft_clip_weights(cloth, scene.pins)) {
        if (state.pinned[w.particle] != 0) continue;
        const double share = kClipHoldFactor / (w.radius * w.radius) * area[w.particle] * w.weight;
        SoftClipSpring hold{static_cast<std::uint32_t>(w.particle), 0.0f, state.position.get(w.particle),
                            static_cast<float>(share), static_cast<float>(share)};
        hold.stiffness = hold.stiffness_for(derived.settings.springs.structural);
        if (share > 0.0) topology.clip_springs.push_back(hold);
    }
    std::vector<glm::vec3> velocity(n, cloth.velocity);
    return MassSpring(std::move(topology), std::move(state), derived.settings, velocity);
}

}  // namespace

MassSpring build_simulation(const Scene& scene) {
    validate(scene);
    if (scene.cloth.is_mesh()) return build_mesh_simulation(scene);
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
    const ShapeMask shape = shape_mask(cloth);
    state.mass = particle_masses(scene, shape);
    state.inverse_mass.resize(n);
    state.pinned.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        state.inverse_mass[i] = shape.particle[i] ? 1.0f / state.mass[i] : 0.0f;
        if (!shape.particle[i]) state.pinned[i] = kAbsent;
    }
    for (std::size_t i : pinned_particles(cloth, scene.pins)) {
        if (state.pinned[i] == kAbsent) continue;  // a preset's pin outside a disc: nothing there to hold
        state.pinned[i] = kPinned;
        state.inverse_mass[i] = 0.0f;
    }
    std::vector<glm::vec3> velocity(n, cloth.velocity);
    Topology topology = grid_topology(shape, state.position, scene.material.enabled);
    // The springs' k from the material here too, for a scene changed in code after it was loaded.
    Scene derived = scene;
    derive_springs(derived);
    // Soft clips: each particle held with k = kappa A w, its rest area A (a quarter of each cell it borders)
    // and its weight w; kappa = kClipHoldFactor E / R^2 per unit area, E the sheet's stretch stiffness, the
    // larger of k_u h_u / h_v and k_v h_v / h_u (a row of springs k every h apart across). A whole disc then
    // holds with kappa R^2 (pi / 3) = 4.2 E in all: the clip gives under a load a quarter of what a square of
    // the cloth stretches under it. R is taken at least one spacing, so a clip that holds its own particle
    // only holds it with k <= 4 E.
    const glm::dvec3 du_axis = glm::dvec3(u) * double(du), dv_axis = glm::dvec3(v) * double(dv);
    const double cell_area = glm::length(glm::cross(du_axis, dv_axis));
    const double aspect = du > 0.0f && dv > 0.0f ? double(du) / double(dv) : 1.0;  // h_u / h_v
    const double spacing = std::max(du, dv);
    for (const ClipWeight& w : soft_clip_weights(cloth, scene.pins)) {
        if (state.pinned[w.particle] != 0) continue;  // absent, or a rigid point pin
        const int r = static_cast<int>(w.particle / cloth.cols), c = static_cast<int>(w.particle % cloth.cols);
        const int cells = shape.has_cell(r - 1, c - 1) + shape.has_cell(r - 1, c) + shape.has_cell(r, c - 1) +
                          shape.has_cell(r, c);
        const double radius = std::max(w.radius, spacing);
        const double share = kClipHoldFactor / (radius * radius) * (0.25 * cells * cell_area) * w.weight;
        SoftClipSpring hold{static_cast<std::uint32_t>(w.particle), 0.0f, state.position.get(w.particle),
                  static_cast<float>(share * aspect), static_cast<float>(share / aspect)};
        hold.stiffness = hold.stiffness_for(derived.settings.springs.structural);
        if (share > 0.0) topology.clip_springs.push_back(hold);  // kept at k = 0 too: the springs may be raised later
    }
    return MassSpring(std::move(topology), std::move(state), derived.settings, velocity);
}

}  // namespace clothsim
