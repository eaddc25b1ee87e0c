#include "clothsim/stepper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

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
        // An integrator with implicit springs is stable at large steps (its limit is contact's or damping's at
        // most): its substeps are a choice of accuracy, which auto substeps raises to the limit but never
        // lowers (XPBD at 1 substep is stable and far softer than its springs).
        if (integrator_info(integration.integrator).implicit_springs) {
            wanted = std::max(wanted, integration.substeps);
        }
        sim.set_substeps(wanted);
    }
    return sim.settings().integration.substeps;
}

StepReport Stepper::advance(MassSpring& sim, double seconds) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    accumulator_ += seconds;
    choose_substeps(sim);  // also when no step is owed: auto substeps follows the panel's edits
    const double dt = sim.settings().integration.dt;
    StepReport report;
    for (;;) {
        if (accumulator_ < dt) break;
        if (report.steps > 0 && std::chrono::duration<double>(Clock::now() - start).count() >= policy_.frame_budget) {
            // Over budget with whole steps still owed: they are dropped, the fraction of a step is kept.
            const double owed = std::floor(accumulator_ / dt) * dt;
            report.dropped_seconds = owed;
            accumulator_ -= owed;
            break;
        }
        const StepReport one = run(sim, 1);
        accumulator_ -= dt;
        report.steps += one.steps;
        report.guard_log += one.guard_log;
        report.guard_gave_up = one.guard_gave_up;
        report.skipped_non_finite = one.skipped_non_finite;
        if (one.steps == 0 || one.guard_gave_up) {  // nothing more to step this frame: owe nothing
            accumulator_ = 0.0;
            break;
        }
    }
    return report;
}

StepReport Stepper::run(MassSpring& sim, long long steps) {
    StepReport report;
    choose_substeps(sim);
    if (steps <= 0) return report;
    if (!sim.asleep() && !sim.all_finite()) {
        report.skipped_non_finite = true;
        return report;
    }
    if (policy_.guard) {
        report.guard_gave_up = !run_guarded(sim, steps, policy_.guard_settings, report.guard_log, last_good_);
        // The guard chose the substeps that held; when nothing held it chose none and the substeps are as before.
        if (!report.guard_log.empty() && !report.guard_gave_up && policy_.auto_substeps) {
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
