#include "integrators.hpp"

namespace clothsim {

void accelerations(const State& state, const Vec3Array& force, glm::vec3 gravity, float damping, Vec3Array& out) {
    out.resize(state.size());
    const float inv_h = state.substep > 0.0f ? 1.0f / state.substep : 0.0f;
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) continue;
        const glm::vec3 v = state.motion.get(i) * inv_h;
        out.set(i, force.get(i) * state.inverse_mass[i] + gravity - damping * v);
    }
}

void step_symplectic_euler(State& state, const Dynamics& dynamics, float h) {
    Vec3Array force, a;
    force.resize(state.size());
    dynamics.forces(state, force);
    accelerations(state, force, dynamics.gravity, dynamics.damping, a);
    // With motion = v h: v' h = v h + a h^2, then x' = x + v' h.
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) {
            state.motion.set(i, glm::vec3(0.0f));
            continue;
        }
        const glm::vec3 moved = state.motion.get(i) + a.get(i) * (h * h);
        state.motion.set(i, moved);
        state.position.add(i, moved);
    }
    state.substep = h;
}

}  // namespace clothsim
