#include "simulation/sleep_monitor.hpp"

#include <glm/geometric.hpp>

namespace clothsim {

void SleepMonitor::check(State& state, const SolverSettings& solver, double h, bool driven) {
    const std::size_t n = state.size();
    const double elapsed = state.time - reference_time_;
    if (reference_.size() != n || !(elapsed > 0.0)) {
        reference_ = state.position;
        reference_time_ = state.time;
        return;
    }
    const double step_limit = solver.sleep_speed * elapsed;
    const double substep_limit = kSubstepFactor * solver.sleep_speed * h;
    const double step2 = step_limit * step_limit, substep2 = substep_limit * substep_limit;
    bool calm = !driven;
    for (std::size_t i = 0; i < n && calm; ++i) {
        if (state.pinned[i]) continue;
        const glm::dvec3 d = state.position.get(i) - reference_.get(i);
        const glm::dvec3 m = state.motion.get(i);
        calm = glm::dot(d, d) < step2 && glm::dot(m, m) < substep2;  // false for NaN
    }
    calm_seconds_ = calm ? calm_seconds_ + elapsed : 0.0;
    reference_ = state.position;
    reference_time_ = state.time;
    if (calm && calm_seconds_ + 1e-9 >= solver.sleep_time) {
        asleep_ = true;
        for (std::size_t i = 0; i < n; ++i) state.motion.set(i, glm::dvec3(0.0));
    }
}

bool SleepMonitor::wake() {
    calm_seconds_ = 0.0;
    reference_ = DVec3Array{};  // the next check starts a new baseline
    const bool was = asleep_;
    asleep_ = false;
    return was;
}

}  // namespace clothsim
