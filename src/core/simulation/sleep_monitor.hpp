// Sleep: a cloth that has come to rest skips its substeps (only the clock advances) until something could move
// it again (MassSpring::wake: any setting applied, a grab, a pin moved, an edit). The monitor decides when.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

namespace clothsim {

class SleepMonitor {
public:
    bool asleep() const { return asleep_; }
    // s: how long the cloth has stayed under solver.sleep_speed (it sleeps at solver.sleep_time).
    double calm_seconds() const { return calm_seconds_; }
    // Once per step. A particle's speed is its displacement since the last check over the time between: a
    // step-long baseline, because float round-off keeps stiff springs jittering from substep to substep at a
    // few mm/s (measured on the hanging scene: 2.3 mm/s at rest) while the step-to-step drift of a cloth at
    // rest is far smaller. So a vibration the baseline could alias away cannot sleep either, no particle's
    // substep motion may exceed kSubstepFactor x sleep_speed. NaN never counts as calm, nor does a cloth
    // something `driven` (a pin on its way). Falling asleep sets every motion to zero.
    void check(State& state, const SolverSettings& solver, double h, bool driven);
    // Starts the count towards sleep again; returns whether the cloth was asleep (its motion must restart).
    bool wake();

private:
    static constexpr double kSubstepFactor = 100.0;
    bool asleep_ = false;
    double calm_seconds_ = 0.0;
    DVec3Array reference_;        // m: positions at the last check (empty: none since waking)
    double reference_time_ = 0.0;
};

}  // namespace clothsim
