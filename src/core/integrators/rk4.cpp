#include "integrators/integrators.hpp"
#include "integrators/integrator_step.hpp"

namespace clothsim {

template <class F>
void step_rk4(State& state, const BasicDynamics<F>& dynamics, double h) {
    using Vec = glm::dvec3;
    const std::size_t n = state.size();
    state.substep = h;
    // Stage derivatives of (x, v): dx = v, dv = a(x, v). A stage state carries x + c h dx and v + c h dv.
    BasicVec3Array<F> force;
    DVec3Array kv[4], kx[4];
    State stage = state;
    auto evaluate = [&](const State& s, int k) {
        force.resize(n);
        dynamics.forces(s, force);
        accelerations(s, force, dynamics.gravity, dynamics.damping, kv[k]);
        kx[k].resize(n);
        for (std::size_t i = 0; i < n; ++i) kx[k].set(i, s.motion.get(i) / h);
    };
    auto advance_stage = [&](int k, double c) {
        for (std::size_t i = 0; i < n; ++i) {
            stage.position.set(i, state.position.get(i) + kx[k].get(i) * (c * h));
            stage.motion.set(i, state.motion.get(i) + kv[k].get(i) * (c * h * h));
        }
    };
    evaluate(state, 0);
    advance_stage(0, 0.5);
    evaluate(stage, 1);
    advance_stage(1, 0.5);
    evaluate(stage, 2);
    advance_stage(2, 1.0);
    evaluate(stage, 3);
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) {
            state.motion.set(i, Vec(0.0));
            continue;
        }
        const Vec dx = (kx[0].get(i) + 2.0 * kx[1].get(i) + 2.0 * kx[2].get(i) + kx[3].get(i)) * (h / 6.0);
        const Vec dv = (kv[0].get(i) + 2.0 * kv[1].get(i) + 2.0 * kv[2].get(i) + kv[3].get(i)) * (h / 6.0);
        state.position.add(i, dx);
        state.motion.add(i, dv * h);
    }
}
template void step_rk4<float>(State&, const Dynamics&, double);
template void step_rk4<double>(State&, const BasicDynamics<double>&, double);

void rk4_substep(IntegratorContext& c) { step_rk4(c.state, c.dynamics, c.h); }

}  // namespace clothsim
