#include "integrators.hpp"

namespace clothsim {

void step_rk4(State& state, const Dynamics& dynamics, float h) {
    const std::size_t n = state.size();
    state.substep = h;
    // Stage derivatives of (x, v): dx = v, dv = a(x, v). A stage state carries x + c h dx and v + c h dv.
    Vec3Array force, kv[4], kx[4];
    State stage = state;
    auto evaluate = [&](const State& s, int k) {
        force.resize(n);
        dynamics.forces(s, force);
        accelerations(s, force, dynamics.gravity, dynamics.damping, kv[k]);
        kx[k].resize(n);
        for (std::size_t i = 0; i < n; ++i) kx[k].set(i, s.motion.get(i) / h);
    };
    auto advance_stage = [&](int k, float c) {
        for (std::size_t i = 0; i < n; ++i) {
            stage.position.set(i, state.position.get(i) + kx[k].get(i) * (c * h));
            stage.motion.set(i, state.motion.get(i) + kv[k].get(i) * (c * h * h));
        }
    };
    evaluate(state, 0);
    advance_stage(0, 0.5f);
    evaluate(stage, 1);
    advance_stage(1, 0.5f);
    evaluate(stage, 2);
    advance_stage(2, 1.0f);
    evaluate(stage, 3);
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) {
            state.motion.set(i, glm::vec3(0.0f));
            continue;
        }
        const glm::vec3 dx = (kx[0].get(i) + 2.0f * kx[1].get(i) + 2.0f * kx[2].get(i) + kx[3].get(i)) * (h / 6.0f);
        const glm::vec3 dv = (kv[0].get(i) + 2.0f * kv[1].get(i) + 2.0f * kv[2].get(i) + kv[3].get(i)) * (h / 6.0f);
        state.position.add(i, dx);
        state.motion.add(i, dv * h);
    }
}

}  // namespace clothsim
