// Small scene builders shared by the physics tests.
#pragma once

#include "clothsim/material.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>

namespace clothsim::test {

// The heavy elastica: B theta'' = -q (L - s) cos(theta), theta(0) = 0, theta'(L) = 0, q = density g (a clamped
// strip under its own weight). Solved by shooting on theta'(0) (bisection; the residual theta'(L) grows with it)
// with RK4 in s; returns the tip drop, the integral of sin(theta) ds.
inline double elastica_tip_drop(double length, double bending, double q) {
    const int n = 4000;
    const double ds = length / n;
    auto shoot = [&](double kappa0, double* drop) {
        double theta = 0.0, kappa = kappa0, y = 0.0;
        auto f = [&](double s, double th, double ka) {
            return std::array<double, 3>{ka, -q / bending * (length - s) * std::cos(th), std::sin(th)};
        };
        for (int i = 0; i < n; ++i) {
            const double s = i * ds;
            const auto k1 = f(s, theta, kappa);
            const auto k2 = f(s + ds / 2, theta + ds / 2 * k1[0], kappa + ds / 2 * k1[1]);
            const auto k3 = f(s + ds / 2, theta + ds / 2 * k2[0], kappa + ds / 2 * k2[1]);
            const auto k4 = f(s + ds, theta + ds * k3[0], kappa + ds * k3[1]);
            theta += ds / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]);
            kappa += ds / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]);
            y += ds / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]);
        }
        if (drop) *drop = y;
        return kappa;  // theta'(L)
    };
    double lo = 0.0, hi = q * length * length / bending;  // theta'(L) < 0 at lo, > 0 at the linear moment bound
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (shoot(mid, nullptr) < 0.0 ? lo : hi) = mid;
    }
    double drop = 0.0;
    shoot(0.5 * (lo + hi), &drop);
    return drop;
}

// The largest distance between the same particle of two cloths (m).
inline double largest_distance(const MassSpring& a, const MassSpring& b) {
    double worst = 0.0;
    for (std::size_t i = 0; i < a.particle_count(); ++i) {
        worst = std::max(worst, glm::length(a.state().position.get(i) - b.state().position.get(i)));
    }
    return worst;
}

// Free particles of one mass at the given positions, at rest: every state array sized, nothing pinned.
inline State free_particles(std::initializer_list<glm::vec3> positions, float mass) {
    State st;
    st.position.resize(positions.size());
    st.motion.resize(positions.size());
    std::size_t i = 0;
    for (const glm::vec3& p : positions) st.position.set(i++, p);
    st.mass.assign(positions.size(), mass);
    st.inverse_mass.assign(positions.size(), 1.0f / mass);
    st.pinned.assign(positions.size(), 0);
    return st;
}

// n free particles of mass 1 at the origin, at rest.
inline State free_state(std::size_t n) {
    State st;
    st.position.resize(n);
    st.motion.resize(n);
    st.mass.assign(n, 1.0f);
    st.inverse_mass.assign(n, 1.0f);
    st.pinned.assign(n, 0);
    return st;
}

// A vertical chain of `particles` particles spaced `spacing` apart hanging down from the origin, with only
// structural springs of stiffness k, no gravity, no damping, no colliders, nothing pinned.
inline Scene chain(int particles, float spacing, float particle_mass, float k) {
    Scene s;
    s.cloth.rows = particles;
    s.cloth.cols = 1;
    s.cloth.size = {1.0f, particles > 1 ? spacing * static_cast<float>(particles - 1) : 1.0f};
    s.cloth.mass = particle_mass * static_cast<float>(particles);
    s.cloth.origin = {0.0f, 0.0f, 0.0f};
    s.pins.preset = PinPreset::None;
    s.settings.springs = {glm::vec2(k), 0.0f, glm::vec2(0.0f), 0.0f};
    s.settings.forces.gravity = {0.0f, 0.0f, 0.0f};
    s.settings.colliders.shapes.clear();
    s.settings.integration.substeps = 1;
    return s;
}

// The first collider of a kind, by its first-form section name (sphere, cube, cylinder, ground): added switched
// off where the first form put it when the list has none (scene.hpp: first_form_collider); a const list must
// hold one.
inline Collider& collider(ColliderSettings& c, std::string_view section) { return first_form_collider(c, section); }
inline const Collider& collider(const ColliderSettings& c, std::string_view section) {
    const int kind = find_collider_kind(section);
    for (const Collider& x : c.shapes) {
        if (static_cast<int>(x.kind()) == kind) return x;
    }
    throw std::logic_error("the scene has no " + std::string(section));
}
template <class Shape, class Colliders>
auto& shape_of(Colliders& c, std::string_view section) {
    return std::get<Shape>(collider(c, section).shape);
}
inline auto& sphere(auto& c) { return shape_of<SphereCollider>(c, "sphere"); }
inline auto& box(auto& c) { return shape_of<BoxCollider>(c, "cube"); }
inline auto& cylinder(auto& c) { return shape_of<CylinderCollider>(c, "cylinder"); }
inline auto& plane(auto& c) { return shape_of<PlaneCollider>(c, "ground"); }

// Whether two simulations hold the same positions and motion, bit for bit.
inline bool bit_identical(const MassSpring& a, const MassSpring& b) {
    const State& sa = a.state();
    const State& sb = b.state();
    const std::size_t bytes = sa.size() * sizeof(sa.position.x[0]);
    return sa.size() == sb.size() && std::memcmp(sa.position.x.data(), sb.position.x.data(), bytes) == 0 &&
           std::memcmp(sa.position.y.data(), sb.position.y.data(), bytes) == 0 &&
           std::memcmp(sa.position.z.data(), sb.position.z.data(), bytes) == 0 &&
           std::memcmp(sa.motion.x.data(), sb.motion.x.data(), bytes) == 0 &&
           std::memcmp(sa.motion.y.data(), sb.motion.y.data(), bytes) == 0 &&
           std::memcmp(sa.motion.z.data(), sb.motion.z.data(), bytes) == 0;
}

// Changes `sim`'s live settings through its one call (MassSpring::apply), as the panel does.
template <class Edit>
void edit_settings(clothsim::MassSpring& sim, Edit edit) {
    clothsim::SimulationSettings settings = sim.settings();
    edit(settings);
    sim.apply(settings);
}

// A free 12 x 12 sheet in zero gravity, undamped, tearing beyond 20% strain, whose left half moves left and
// right half moves right at `speed` (m/s): it tears down the middle.
inline MassSpring pulled_apart(SolverMethod method, float speed) {
    Scene s;
    s.cloth.rows = s.cloth.cols = 12;
    s.pins.preset = PinPreset::None;
    s.settings.forces.gravity = glm::vec3(0.0f);
    s.settings.colliders.shapes.clear();
    s.settings.springs.damping = 0.0f;
    s.settings.springs.tear_strain = 0.2f;
    s.settings.solver.method = method;
    s.settings.solver.sleep_speed = 0.0f;
    MassSpring sim = build_simulation(s);
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const int col = static_cast<int>(i) % 12;
        sim.set_particle(i, sim.position(i), glm::vec3(col < 6 ? -speed : speed, 0.0f, 0.0f));
    }
    return sim;
}

// A Cusick specimen: a 30 cm disc of n x n grid particles lying flat at y = 1, centred on the y axis,
// nothing pinned, ground off.
inline Scene disc_specimen(int n) {
    Scene s;
    s.cloth.rows = s.cloth.cols = n;
    s.cloth.size = {0.3f, 0.3f};
    s.cloth.origin = {-0.15f, 1.0f, -0.15f};
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.0f, 0.0f, 1.0f};
    s.cloth.shape = ClothShape::Disc;
    s.pins.preset = PinPreset::None;
    s.settings.colliders.shapes.clear();
    return s;
}

// The sanitizer build (AddressSanitizer + UBSan) looks for memory and undefined-behaviour errors, which the
// first steps of a loop reach as well as its last: the loops over every bundled scene run a quarter of their
// steps or frames there (kLoopShare); the Release suite runs them whole and checks the physics. The tests
// tagged [convergence] (resolution studies, the settled Cusick drape) run in the Release suite only
// (tests/CMakeLists.txt).
#if defined(__SANITIZE_ADDRESS__)
inline constexpr int kLoopShare = 4;
inline constexpr bool kSanitized = true;
#else
inline constexpr int kLoopShare = 1;
inline constexpr bool kSanitized = false;
#endif

// The bundled scenes that cost far more per step than the others, and how the tests that run every bundled
// scene keep them cheap. stiff-hanging and stiff-drape are cotton at its measured stretch on a fine grid, so
// explicit Verlet needs 384 substeps per step at 64 x 64 and 645 at 128 x 128: 1.6e6 and 1.1e7
// particle-substeps per step, where the others take 1.1e5 to 2.2e5 (cusick, a 41 x 41 disc at 1000: 1.7e6).
// CI runs the suite in Release and again under AddressSanitizer on 2 cores; at full size the two added 28 s
// (Release) to a loop of 2 simulated seconds, and 60 s to the render test.
// - Simulation loops (and the golden hashes) run them on a `loop_side` x `loop_side` grid: a material scene
//   is then the same fabric (springs and masses are derived from the grid) with the file's substeps, well
//   inside its stable range there. These runs check loading, building, contact, pins and determinism, not the
//   scene's stability at its own size: that is checked at full size by `stability every bundled scene steps
//   inside its predicted limit` (the bound) and by one full-size step in `scene: every bundled scene loads,
//   builds and stays finite ...`.
// - The render test draws them at full size for `render_frames` frames instead of 60: its cost is the frames
//   (about 0.22 s each under Xvfb in Release, plus 1.5 s to start), not the simulation.
struct CostlyScene {
    std::string_view scene;
    int loop_side;      // particles per side in the simulation loops
    int render_frames;  // frames drawn by the render test
};
// pile and fold run self-collision, which costs several times their step (docs/SELF_COLLISION.md); their
// own test (tests/core/test_self_collision.cpp) runs them at full size.
inline constexpr std::array<CostlyScene, 4> kCostlyScenes = {{
    {"stiff-drape", 24, 10},
    {"stiff-hanging", 24, 10},
    {"pile", 16, 30},
    {"fold", 16, 30},
}};

inline const CostlyScene* costly_scene(std::string_view scene) {
    for (const CostlyScene& c : kCostlyScenes) {
        if (c.scene == scene) return &c;
    }
    return nullptr;
}

// load_scene(name) as shipped, or on the coarser grid above for a costly scene.
inline Scene scene_for_loops(std::string_view name) {
    Scene s = load_scene(name);
    if (const CostlyScene* c = costly_scene(name)) s.cloth.rows = s.cloth.cols = c->loop_side;
    return s;
}

// A tensile test specimen: a square sheet of `per_side` particles, 0.3 m a side, of `material`, no gravity or
// ground, held by its first and last columns (along u) or rows (along v), the far one moved out by `strain`,
// then settled: damped at critical for its slowest in-plane mode at `stiffness` (N/m; w ~ pi sqrt(S /
// density) / side) and run to e^-20 at `safety` of the critical substep.
inline MassSpring pulled_sheet(int per_side, bool along_u, const MaterialSettings& material, double strain,
                               double stiffness, float safety) {
    Scene s;
    const float side = 0.3f;
    s.cloth.rows = s.cloth.cols = per_side;
    s.cloth.size = {side, side};
    s.cloth.origin = {0.0f, 0.0f, 0.0f};
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.0f, 1.0f, 0.0f};
    s.pins.preset = along_u ? PinPreset::LeftEdge : PinPreset::TopRow;
    s.settings.forces.gravity = {0.0f, 0.0f, 0.0f};
    collider(s.settings.colliders, "ground").enabled = false;
    s.settings.solver.sleep_speed = 0.0f;
    s.material = material;
    s.material.enabled = true;
    derive_springs(s);
    MassSpring sim = build_simulation(s);
    for (int i = 0; i < per_side; ++i) {
        const std::size_t p = along_u ? static_cast<std::size_t>(i) * per_side + per_side - 1
                                      : static_cast<std::size_t>(per_side - 1) * per_side + i;
        sim.set_pinned(p, true);
        glm::vec3 x = sim.position(p);
        (along_u ? x.x : x.y) *= static_cast<float>(1.0 + strain);
        sim.move_pinned(p, x);
    }
    const double w = 3.14159 * std::sqrt(stiffness / double(material.density)) / side;
    SimulationSettings settings = sim.settings();
    settings.springs.damping = static_cast<float>(2.0 * w);
    sim.apply(settings);
    sim.set_substeps(auto_substeps(stability_limit(sim), settings.integration.dt, safety, 1));
    sim.run_steps(static_cast<long long>(std::ceil(20.0 / w / settings.integration.dt)));
    return sim;
}

}  // namespace clothsim::test
