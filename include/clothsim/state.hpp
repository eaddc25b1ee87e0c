// Setup apart from state (as Jolt's SoftBodySharedSettings / SoftBodyMotionProperties):
//  - Topology is built once per cloth: grid shape, spring list, triangles.
//  - State changes every step and is laid out as structure of arrays for the hot loops.
#pragma once

#include "clothsim/aligned_allocator.hpp"
#include "clothsim/settings.hpp"
#include "clothsim/spring.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace clothsim {

// Three coordinate arrays of equal length: the layout the spring and integration loops want. Double for
// positions and motion (State), float for forces (the spring kernels compute in float), double for the
// forces of the reference solution (reference.hpp).
template <class T>
struct BasicVec3Array {
    using Vec = glm::vec<3, T>;
    AlignedVector<T> x, y, z;  // each starts on a cache line

    std::size_t size() const { return x.size(); }
    void resize(std::size_t n, T value = T(0)) {
        x.assign(n, value);
        y.assign(n, value);
        z.assign(n, value);
    }
    Vec get(std::size_t i) const { return {x[i], y[i], z[i]}; }
    void set(std::size_t i, Vec v) {
        x[i] = v.x;
        y[i] = v.y;
        z[i] = v.z;
    }
    void add(std::size_t i, Vec v) {
        x[i] += v.x;
        y[i] += v.y;
        z[i] += v.z;
    }
    bool operator==(const BasicVec3Array&) const = default;
};
using Vec3Array = BasicVec3Array<float>;
using DVec3Array = BasicVec3Array<double>;

// Values of State::pinned besides 0 (free). An absent particle is a grid slot outside the cloth's shape (a
// disc, settings.hpp): it has no mass, springs, bends or triangles, never moves, and is neither drawn nor
// picked. Keeping the slot keeps the grid's layout for the fast solver.
inline constexpr std::uint8_t kPinned = 1;
inline constexpr std::uint8_t kAbsent = 2;

// A particle of a soft clip (ClipKind::Soft), held to its anchor, where it lay at rest, by a zero-length
// spring: F = -k (x - anchor), k = max(k_u share_u, k_v share_v) with k_u, k_v the structural springs' constants
// (kept up to date when they change; cloth_builder.cpp has the shares).
struct SoftClipSpring {
    std::uint32_t particle = 0;
    float stiffness = 0.0f;  // N/m
    glm::dvec3 anchor{0.0};  // m
    float share_u = 0.0f, share_v = 0.0f;
    float stiffness_for(const glm::vec2& structural) const {
        return std::max(structural.x * share_u, structural.y * share_v);
    }
};

// A grid cloth has rows x cols particles, row-major. A mesh cloth (cloth.mesh) is stored as one row of its
// vertices (rows = 1): what reads rows and columns sees a single row, and no grid kernel takes it (their
// layouts need the grid's springs).
struct Topology {
    int rows = 0;
    int cols = 0;
    std::vector<Spring> springs;
    std::vector<Bend> bends;  // the material form's bending (kind Bending); the per-spring form has none
    std::vector<Hinge> hinges;  // a mesh cloth's bending (kind Bending), instead of bends
    // A mesh cloth's constant-strain triangles (cloth.membrane = "triangles"): its stretch and shear, where its
    // edge springs then have weight 0 (they still measure strain and tear).
    std::vector<Membrane> membranes;
    GaussianCurvature gaussian;  // a flat mesh cloth's: its hinges' Poisson coupling taken out (spring.hpp)
    std::vector<SoftClipSpring> clip_springs;  // soft clips' particles (pins with clip = "soft")
    std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from u_axis x v_axis
    // The triangles are every grid cell's two, in row-major cell order: (00, 01, 10) and (01, 11, 10) for the
    // cell's corners (row, col) = 00. The builder sets it for rectangles; normals.cpp then sweeps the grid.
    bool cell_triangles = false;
    std::array<std::size_t, kSpringKindCount> spring_count_by_kind{};  // bends count as Bending

    std::size_t index(int row, int col) const { return static_cast<std::size_t>(row) * cols + col; }
    // Fills spring_count_by_kind from the lists (after a hand-made topology or a tear changed them).
    void count_by_kind() {
        spring_count_by_kind = {};
        for (const Spring& s : springs) ++spring_count_by_kind[static_cast<int>(s.kind)];
        spring_count_by_kind[static_cast<int>(SpringKind::Bending)] += bends.size() + hinges.size();
    }
    // A triangle mesh cloth (cloth.mesh): its particles are the mesh's vertices, rows = 1 and cols their count.
    bool mesh = false;
    bool material_weights = false;  // a mesh cloth's weights are the material form's (cloth_mesh.hpp)
    // A mesh cloth's texture coordinates (m), one per particle: its rest shape projected on u_axis and on the
    // direction across it in the mesh's mean plane (the weave's warp and weft). Empty for a grid (grid_uv).
    std::vector<glm::vec2> uv;
};

// Per component, the smallest and largest motion of one substep (pinned and absent particles' zero included).
// |m_j - m_i| <= |hi - lo| bounds how much any two particles closed in during it, which is what
// self-collision's conservative advancement spends its budget on (self_collision.hpp). Empty until a particle
// is included; a NaN component may be lost (a cloth that is not finite is the guard's).
struct MotionBounds {
    glm::dvec3 lo{0.0}, hi{0.0};
    bool empty = true;

    void include(const MotionBounds& other) {
        if (other.empty) return;
        lo = empty ? other.lo : glm::min(lo, other.lo);
        hi = empty ? other.hi : glm::max(hi, other.hi);
        empty = false;
    }
    double spread() const { return glm::length(hi - lo); }
    // A bound on any particle's motion.
    double largest() const { return glm::length(glm::max(glm::abs(lo), glm::abs(hi))); }
};

// The simulation state, in double precision. A substep changes a position by its motion, which at small
// substeps is far below a float position's resolution: at h = 3e-5 s a cloth at rest under gravity first
// moves by g h^2 = 9e-9 m, under half a float ulp at 1.6 m (6e-8 m), and a float state loses it (the
// cloth freezes), or rounds every substep's update the same way (the error grows with the substep count).
// In double the update keeps 29 more bits: at 4096 substeps per 1/60 s step the relative rounding per
// substep is 1e-16 and 2.5e5 of them cost 3e-11 (docs/ACCURACY.md has the measurements). What does not
// accumulate stays float, which keeps the spring kernels' speed: forces (from each spring's difference
// x_b - x_a taken in double and rounded once), masses, and the substep's velocity change a h^2 (rounded
// once per substep, relative 6e-8, the force's own precision) before it is added to the double motion.
struct State {
    DVec3Array position;  // m
    // m: x - x_prev, the motion of the last substep. Position Verlet's previous positions are x - motion.
    // Keeping the difference instead of x_prev is the same scheme with less round-off: the difference
    // keeps full relative precision, while x_prev would lose the small per-step motion to x's rounding.
    DVec3Array motion;
    // Parameters, not accumulators: float is exact enough and halves what the integration loops read.
    std::vector<float> mass;          // kg (kept for pinned particles too, for energy and momentum)
    AlignedVector<float> inverse_mass;  // 1/kg, 0 for pinned particles (read with the rows)
    std::vector<std::uint8_t> pinned;  // 0 free, else kPinned or kAbsent: either never moves
    double time = 0.0;     // s
    double substep = 0.0;  // s: the substep `motion` belongs to
    // Which integrator's convention `motion` follows: Verlet keeps x - x_prev; every other integrator keeps
    // v h, its velocity times the substep (the same displacement a substep at that velocity makes).
    Integrator integrator = Integrator::Verlet;

    std::size_t size() const { return position.size(); }
};

}  // namespace clothsim
