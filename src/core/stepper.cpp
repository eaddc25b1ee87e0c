#include "clothsim/stepper.hpp"

#include <algorithm>

namespace clothsim {

const StabilityLimit& Stepper::limit(const MassSpring& sim) {
    if (limit_stamp_ != sim.setup_stamp()) {
        limit_ = stability_limit(sim);
        limit_stamp_ = sim.setup_stamp();
    }
    return limit_;
}

int Stepper::choose_substeps(MassSpring& sim) {
    if (policy_.auto_substeps) {
        const IntegrationSettings& integration = sim.settings().integration;
        int wanted = auto_substeps(limit(sim), integration.dt, policy_.safety);
        // Implicit Euler, projective and XPBD are stable at large steps (their limit is contact's or damping's
        // at most): their substeps are a choice of accuracy, which auto substeps raises to the limit but never
        // lowers (XPBD at 1 substep is stable and far softer than its springs).
        const Integrator integrator = integration.integrator;
        if (integrator == Integrator::ImplicitEuler || integrator == Integrator::Projective ||
            integrator == Integrator::Xpbd) {
            wanted = std::max(wanted, integration.substeps);
        }
        sim.set_substeps(wanted);
    }
    return sim.settings().integration.substeps;
}

StepReport Stepper::advance(MassSpring& sim, double seconds) {
    choose_substeps(sim);
    const double dt = sim.settings().integration.dt;
    accumulator_ += seconds;
    long long steps = static_cast<long long>(accumulator_ / dt);
    double dropped = 0.0;
    if (steps > policy_.max_catchup_steps) {
        dropped = static_cast<double>(steps - policy_.max_catchup_steps) * dt;
        steps = policy_.max_catchup_steps;
        accumulator_ = 0.0;
    } else {
        accumulator_ -= static_cast<double>(steps) * dt;
    }
    StepReport report = run(sim, steps);
    report.dropped_seconds = dropped;
    return report;
}

StepReport Stepper::run(MassSpring& sim, long long steps) {
    StepReport report;
    choose_substeps(sim);
    if (steps <= 0) return report;
    if (!sim.resting() && !sim.all_finite()) {
        report.skipped_non_finite = true;
        return report;
    }
    if (policy_.guard) {
        report.guard_gave_up = !run_guarded(sim, steps, policy_.guard_settings, report.guard_log);
        if (!report.guard_log.empty() && policy_.auto_substeps) {
            policy_.auto_substeps = false;
            report.guard_log += "auto substeps turned off to keep the guard's choice\n";
        }
    } else {
        sim.run_steps(steps);
    }
    report.steps = steps;
    return report;
}

}  // namespace clothsim
