// The run policy: how time becomes steps of a MassSpring. The caller owns time (as in b2World_Step); the
// Stepper decides how many whole steps of integration.dt to run and with how many substeps, in one place
// that the desktop app and --headless both use:
//  - fixed step: advance() adds simulated seconds to an accumulator and runs the whole steps it holds until
//    they have taken frame_budget of wall time, so a slow frame slows the simulation instead of spiralling
//    (Fiedler, "Fix Your Timestep!", 2004) and a frame never waits long on physics: the cap is time, not a
//    count of steps, whatever a step costs (one step always runs when one is owed); run() runs an exact
//    number of steps (a single step, a scripted frame, a headless run);
//  - auto substeps: before stepping, integration.substeps is chosen so the substep is `safety` times the
//    critical substep of the current cloth (stability.hpp, docs/STABILITY.md);
//  - the guard: a step that blows up is rolled back and retried with twice the substeps (run_guarded). Auto
//    substeps then yields to the guard's choice (it is turned off), so the next step does not fall back to
//    the substep that failed.
#pragma once

#include "clothsim/mass_spring.hpp"
#include "clothsim/stability.hpp"

#include <cstdint>
#include <optional>
#include <string>

namespace clothsim {

struct RunPolicy {
    bool auto_substeps = false;  // choose integration.substeps from the critical substep before stepping
    float safety = 0.5f;         // ... so the substep is this fraction of it, in (0, 1]
    bool guard = false;          // roll back and retry with doubled substeps when a step blows up
    GuardSettings guard_settings;
    // s of wall time: advance() starts no further step once its steps have taken this long; the time still
    // owed is dropped. 50 ms keeps a frame's physics within three frames of 60 Hz.
    double frame_budget = 0.05;
};

// What one advance() or run() did.
struct StepReport {
    long long steps = 0;           // steps run
    double dropped_seconds = 0.0;  // simulated time dropped by the frame budget
    bool skipped_non_finite = false;  // nothing was stepped: the cloth is already non-finite
    bool guard_gave_up = false;    // the guard ran out of retries: the cloth is at the last good state
    std::string guard_log;         // the guard's changes and auto substeps turned off, one line each
};

class Stepper {
public:
    explicit Stepper(RunPolicy policy = {}) : policy_(policy) {}

    const RunPolicy& policy() const { return policy_; }
    void set_auto_substeps(bool on) { policy_.auto_substeps = on; }
    void set_safety(float safety) { policy_.safety = safety; }
    void set_frame_budget(double seconds) { policy_.frame_budget = seconds; }

    // Adds `seconds` of simulated time and runs the whole steps of integration.dt it makes up (with what
    // earlier calls left over), one after another until they have taken frame_budget of wall time; the time
    // still owed then is dropped (StepReport::dropped_seconds).
    StepReport advance(MassSpring& sim, double seconds);
    // Runs `steps` steps now.
    StepReport run(MassSpring& sim, long long steps);
    // Forgets the time owed (a new cloth, a reset).
    void restart() { accumulator_ = 0.0; }

    // Chooses integration.substeps when auto substeps is on (run() and advance() do this before stepping);
    // returns the substeps in force.
    int choose_substeps(MassSpring& sim);
    // The stability limit of `sim` as it is now (kept until sim.setup_stamp() changes).
    const StabilityLimit& limit(const MassSpring& sim);

private:
    RunPolicy policy_;
    double accumulator_ = 0.0;       // s of simulated time owed
    StabilityLimit limit_;
    std::uint64_t limit_stamp_ = 0;  // the setup_stamp limit_ was computed for (0: none)
    std::optional<MassSpring> last_good_;  // the guard's copy before each step, its storage kept between steps
};

}  // namespace clothsim
