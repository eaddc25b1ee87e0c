// Small scene builders shared by the physics tests.
#pragma once

#include "clothsim/material.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <utility>
#include <numbers>
#include <map>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

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

// A rows x cols grid of spacing h in the x-z plane, each inner point jittered by up to `jitter` h (seeded), each
// cell split along a diagonal chosen at random: an irregular triangulation, every triangle facing +y.
struct Sheet {
    std::vector<glm::dvec3> rest;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<bool> inner;
};
inline Sheet irregular_sheet(int rows, int cols, double h, double jitter, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-jitter * h, jitter * h);
    Sheet s;
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
            const bool inside = r > 0 && c > 0 && r < rows - 1 && c < cols - 1;
            s.rest.push_back({c * h + (inside ? u(rng) : 0.0), 0.0, r * h + (inside ? u(rng) : 0.0)});
            s.inner.push_back(inside);
        }
    }
    std::bernoulli_distribution flip(0.5);
    auto at = [&](int r, int c) { return static_cast<std::uint32_t>(r * cols + c); };
    for (int r = 0; r + 1 < rows; ++r) {
        for (int c = 0; c + 1 < cols; ++c) {
            // Counter-clockwise seen from +y (x cross z = -y, so the order is a, c, b).
            if (flip(rng)) {
                s.triangles.push_back({at(r, c), at(r + 1, c), at(r, c + 1)});
                s.triangles.push_back({at(r, c + 1), at(r + 1, c), at(r + 1, c + 1)});
            } else {
                s.triangles.push_back({at(r, c), at(r + 1, c + 1), at(r, c + 1)});
                s.triangles.push_back({at(r, c), at(r + 1, c), at(r + 1, c + 1)});
            }
        }
    }
    return s;
}

inline DVec3Array positions(const std::vector<glm::dvec3>& p) {
    DVec3Array out;
    out.resize(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) out.set(i, p[i]);
    return out;
}

// A triangle mesh: its vertices and its triangles.
struct Mesh {
    std::vector<glm::dvec3> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

// Signed area of triangle t projected on the x-z plane (the sign is its winding seen from -y).
inline double signed_area(const Mesh& m, const std::array<std::uint32_t, 3>& t) {
    const glm::dvec3 a = m.vertices[t[1]] - m.vertices[t[0]], b = m.vertices[t[2]] - m.vertices[t[0]];
    return 0.5 * (a.z * b.x - a.x * b.z);
}

// Lawson's flips (Lawson 1977): an interior edge whose two opposite angles sum to more than pi is replaced by
// the other diagonal of its quadrilateral, until none is left; the result is the Delaunay triangulation of the
// points (flat, in the x-z plane). Windings are kept.
inline void make_delaunay(Mesh& m) {
    auto angle = [&](std::uint32_t p, std::uint32_t q, std::uint32_t at) {
        const glm::dvec3 a = m.vertices[p] - m.vertices[at], b = m.vertices[q] - m.vertices[at];
        return std::acos(std::clamp(glm::dot(a, b) / (glm::length(a) * glm::length(b)), -1.0, 1.0));
    };
    for (bool flipped = true; flipped;) {
        flipped = false;
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> owner;  // directed edge -> triangle
        for (std::uint32_t t = 0; t < m.triangles.size(); ++t) {
            for (int k = 0; k < 3; ++k) owner[{m.triangles[t][k], m.triangles[t][(k + 1) % 3]}] = t;
        }
        std::vector<std::uint8_t> touched(m.triangles.size(), 0);
        for (std::uint32_t t = 0; t < m.triangles.size(); ++t) {
            for (int k = 0; k < 3 && !touched[t]; ++k) {
                const std::uint32_t a = m.triangles[t][k], b = m.triangles[t][(k + 1) % 3], c = m.triangles[t][(k + 2) % 3];
                const auto other = owner.find({b, a});
                if (other == owner.end() || touched[other->second]) continue;
                const std::uint32_t u = other->second;
                std::uint32_t d = 0;
                for (std::uint32_t i : m.triangles[u]) {
                    if (i != a && i != b) d = i;
                }
                if (angle(a, b, c) + angle(a, b, d) <= std::numbers::pi + 1e-12) continue;
                const double sign = signed_area(m, m.triangles[t]);
                std::array<std::uint32_t, 3> first{c, a, d}, second{c, d, b};
                if (signed_area(m, first) * sign < 0) std::swap(first[1], first[2]);
                if (signed_area(m, second) * sign < 0) std::swap(second[1], second[2]);
                m.triangles[t] = first;
                m.triangles[u] = second;
                touched[t] = touched[u] = 1;
                flipped = true;
            }
        }
    }
}

// An irregular Delaunay triangulation of a `length` x `width` rectangle in the x-z plane with edges about h
// long: a triangular lattice (rows sqrt(3)/2 h apart, odd rows shifted by half a spacing, with a point on each
// end), every point not on the boundary moved by up to jitter x h in x and z (seeded), rows zipped into
// triangles, then Lawson's flips. Statistically isotropic, unlike a grid's cells.
inline Mesh delaunay_rectangle(double h, double length, double width, double jitter, unsigned seed) {
    const int rows = std::max(2, static_cast<int>(std::lround(width / (h * std::sqrt(3.0) / 2.0))) + 1);
    const int cols = std::max(2, static_cast<int>(std::lround(length / h)) + 1);
    const double dx = length / (cols - 1), dz = width / (rows - 1);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> offset(-jitter * h, jitter * h);
    Mesh m;
    std::vector<std::vector<std::uint32_t>> row(rows);
    for (int r = 0; r < rows; ++r) {
        std::vector<double> xs;
        if (r % 2 == 0) {
            for (int c = 0; c < cols; ++c) xs.push_back(c * dx);
        } else {
            xs.push_back(0.0);
            for (int c = 0; c + 1 < cols; ++c) xs.push_back((c + 0.5) * dx);
            xs.push_back(length);
        }
        for (std::size_t c = 0; c < xs.size(); ++c) {
            glm::dvec3 p(xs[c], 0.0, r * dz);
            const bool boundary = r == 0 || r + 1 == rows || c == 0 || c + 1 == xs.size();
            if (!boundary) p += glm::dvec3(offset(rng), 0.0, offset(rng));
            row[r].push_back(static_cast<std::uint32_t>(m.vertices.size()));
            m.vertices.push_back(p);
        }
    }
    for (int r = 0; r + 1 < rows; ++r) {
        const auto &a = row[r], &b = row[r + 1];
        std::size_t i = 0, j = 0;
        while (i + 1 < a.size() || j + 1 < b.size()) {
            if (j + 1 == b.size() || (i + 1 < a.size() && m.vertices[a[i + 1]].x < m.vertices[b[j + 1]].x)) {
                m.triangles.push_back({a[i], a[i + 1], b[j]});
                ++i;
            } else {
                m.triangles.push_back({a[i], b[j + 1], b[j]});
                ++j;
            }
        }
    }
    make_delaunay(m);
    return m;
}

}  // namespace clothsim::test
