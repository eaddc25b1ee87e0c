// Setup apart from state (as Jolt's SoftBodySharedSettings / SoftBodyMotionProperties):
//  - Topology is built once per cloth: grid shape, spring list, triangles.
//  - State changes every step and is laid out as structure of arrays for the hot loops.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/spring.hpp"

#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace clothsim {

// Three coordinate arrays of equal length: the layout the spring and integration loops want. Float for
// the simulation; double for the reference solution (reference.hpp), which runs the same physics code.
template <class T>
struct BasicVec3Array {
    using Vec = glm::vec<3, T>;
    std::vector<T> x, y, z;

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

struct Topology {
    int rows = 0;
    int cols = 0;
    std::vector<Spring> springs;
    std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from u_axis x v_axis
    std::array<std::size_t, kSpringKindCount> spring_count_by_kind{};

    std::size_t index(int row, int col) const { return static_cast<std::size_t>(row) * cols + col; }
};

template <class T>
struct BasicState {
    BasicVec3Array<T> position;   // m
    // m: x - x_prev, the motion of the last substep. Position Verlet's previous positions are x - motion.
    // Keeping the difference instead of x_prev is the same scheme with less round-off: in float, x_prev
    // loses the small per-step motion to x's rounding and the velocity error then grows every step
    // (measured on a 2-particle oscillator at 800 substeps per period over 3 periods: max error 4.4e-5 m
    // with x_prev, 2.4e-6 m with motion; 2.0e-4 m and 1.4e-6 m with damping 2/s). Stored motion keeps
    // full relative precision.
    BasicVec3Array<T> motion;
    std::vector<T> mass;          // kg (kept for pinned particles too, for energy and momentum)
    std::vector<T> inverse_mass;  // 1/kg, 0 for pinned particles
    std::vector<std::uint8_t> pinned;
    double time = 0.0;            // s
    T substep = T(0);             // s: the substep `motion` belongs to
    // Which integrator's convention `motion` follows: Verlet keeps x - x_prev; every other integrator keeps
    // v h, its velocity times the substep (the same displacement a substep at that velocity makes).
    Integrator integrator = Integrator::Verlet;

    std::size_t size() const { return position.size(); }
};
using State = BasicState<float>;
using DState = BasicState<double>;

}  // namespace clothsim
