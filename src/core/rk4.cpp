#include "integrators.hpp"

namespace clothsim {

template <class T>
void step_rk4(BasicState<T>& state, const BasicDynamics<T>& dynamics, T h) {
    using Vec = glm::vec<3, T>;
    const std::size_t n = state.size();
    state.substep = h;
    // Stage derivatives of (x, v): dx = v, dv = a(x, v). A stage state carries x + c h dx and v + c h dv.
    BasicVec3Array<T> force, kv[4], kx[4];
    BasicState<T> stage = state;
    auto evaluate = [&](const BasicState<T>& s, int k) {
        force.resize(n);
        dynamics.forces(s, force);
        accelerations(s, force, dynamics.gravity, dynamics.damping, kv[k]);
        kx[k].resize(n);
        for (std::size_t i = 0; i < n; ++i) kx[k].set(i, s.motion.get(i) / h);
    };
    auto advance_stage = [&](int k, T c) {
        for (std::size_t i = 0; i < n; ++i) {
            stage.position.set(i, state.position.get(i) + kx[k].get(i) * (c * h));
            stage.motion.set(i, state.motion.get(i) + kv[k].get(i) * (c * h * h));
        }
    };
    evaluate(state, 0);
    advance_stage(0, T(0.5));
    evaluate(stage, 1);
    advance_stage(1, T(0.5));
    evaluate(stage, 2);
    advance_stage(2, T(1));
    evaluate(stage, 3);
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) {
            state.motion.set(i, Vec(T(0)));
            continue;
        }
        const Vec dx = (kx[0].get(i) + T(2) * kx[1].get(i) + T(2) * kx[2].get(i) + kx[3].get(i)) * (h / T(6));
        const Vec dv = (kv[0].get(i) + T(2) * kv[1].get(i) + T(2) * kv[2].get(i) + kv[3].get(i)) * (h / T(6));
        state.position.add(i, dx);
        state.motion.add(i, dv * h);
    }
}
template void step_rk4<float>(State&, const Dynamics&, float);
template void step_rk4<double>(DState&, const BasicDynamics<double>&, double);

}  // namespace clothsim
