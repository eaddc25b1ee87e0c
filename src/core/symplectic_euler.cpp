#include "integrators.hpp"

namespace clothsim {

template <class T>
void accelerations(const BasicState<T>& state, const BasicVec3Array<T>& force, glm::vec3 gravity, float damping,
                   BasicVec3Array<T>& out) {
    using Vec = glm::vec<3, T>;
    out.resize(state.size());
    const T inv_h = state.substep > T(0) ? T(1) / state.substep : T(0);
    const Vec g(gravity);
    const T c = damping;
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) continue;
        const Vec v = state.motion.get(i) * inv_h;
        out.set(i, force.get(i) * state.inverse_mass[i] + g - c * v);
    }
}
template void accelerations<float>(const State&, const Vec3Array&, glm::vec3, float, Vec3Array&);
template void accelerations<double>(const DState&, const DVec3Array&, glm::vec3, float, DVec3Array&);

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
