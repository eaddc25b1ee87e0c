#include "integrators/integrators.hpp"
#include "integrators/integrator_step.hpp"

namespace clothsim {

template <class F>
void accelerations(const State& state, const BasicVec3Array<F>& force, glm::vec3 gravity, double damping,
                   DVec3Array& out) {
    out.resize(state.size());
    const double inv_h = state.substep > 0.0 ? 1.0 / state.substep : 0.0;
    const glm::dvec3 g(gravity);
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) continue;
        const glm::dvec3 v = state.motion.get(i) * inv_h;
        out.set(i, glm::dvec3(force.get(i)) * double(state.inverse_mass[i]) + g - damping * v);
    }
}
template void accelerations<float>(const State&, const Vec3Array&, glm::vec3, double, DVec3Array&);
template void accelerations<double>(const State&, const DVec3Array&, glm::vec3, double, DVec3Array&);

void step_symplectic_euler(State& state, const Dynamics& dynamics, double h) {
    Vec3Array force;
    DVec3Array a;
    force.resize(state.size());
    dynamics.forces(state, force);
    accelerations(state, force, dynamics.gravity, dynamics.damping, a);
    // With motion = v h: v' h = v h + a h^2, then x' = x + v' h.
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) {
            state.motion.set(i, glm::dvec3(0.0));
            continue;
        }
        const glm::dvec3 moved = state.motion.get(i) + a.get(i) * (h * h);
        state.motion.set(i, moved);
        state.position.add(i, moved);
    }
    state.substep = h;
}

void symplectic_euler_substep(IntegratorContext& c) { step_symplectic_euler(c.state, c.dynamics, c.h); }

}  // namespace clothsim
