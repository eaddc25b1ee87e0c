// StepProfile: where the time of a step goes, stage by stage (like Box2D's b2Profile).
//
// MassSpring::substep() times each stage it runs with the steady clock and adds it here; a stage the plan
// skips (step_plan.hpp) is not timed at all and shows 0 with the plan's reason. The app reads the profile
// every frame and resets it; `clothsim --headless --json` reports the totals of the run.
#pragma once

#include "clothsim/collider.hpp"

#include <array>
#include <chrono>
#include <cstddef>
#include <string_view>

namespace clothsim {

enum class Stage {
    Springs,     // spring forces (textbook solver and velocity integrators)
    Wind,        // wind forces
    Contact,     // penalty contact forces (colliders.contact = penalty; penalty_contact.hpp)
    SoftClips,   // soft clips' holding forces (pins.clip = "soft")
    Fast,        // fast solver: springs, gravity, damping and the Verlet update, fused row by row
    Integrate,   // the integrator's update (textbook Verlet, or a whole velocity-integrator substep)
    BroadPhase,  // boxes of the particle blocks (when the fast solver did not leave them) and of the whole cloth
    Colliders,   // collisions with every enabled shape (broad and narrow phase; projection contact)
    SelfCollision,  // the cloth against itself (collision.self; self_collision.hpp)
    Tethers,     // long-range attachments to the pins (tethers.hpp)
    StrainLimit, // Provot's strain limit
    SpeedLimit,  // the max_speed clamp
    Tear,        // the once-per-step check for springs beyond springs.tear_strain (tearing.hpp)
    Sleep,       // the once-per-step check of whether the cloth may sleep
    Count,
};
inline constexpr std::size_t kStageCount = static_cast<std::size_t>(Stage::Count);

// Lower-case names, as the panel and the JSON show them.
std::string_view stage_name(Stage stage);

struct StepProfile {
    std::array<double, kStageCount> ms{};         // wall time spent in each stage
    std::array<long long, kStageCount> runs{};    // times the stage ran: once a substep (colliders twice when a
                                                  // strain or speed limit runs; Sleep once a step)
    // Collision broad phase, per collider kind (collider.hpp's ColliderShape index): particle blocks whose box
    // met a collider of that kind and were tested particle by particle, out of all blocks offered to them.
    std::array<long long, kColliderKindCount> blocks_tested{};
    std::array<long long, kColliderKindCount> blocks_offered{};
    // Self-collision: substeps it tested (it skips those whose motion cannot close a gap), tiles boxed, tiles
    // sent to the narrow phase, particle pairs pushed apart.
    long long self_tests = 0, self_tiles = 0, self_tiles_active = 0, self_contacts = 0;
    long long substeps = 0;         // substeps stepped
    long long slept_substeps = 0;   // substeps skipped because the cloth was asleep

    double total_ms() const {
        double t = 0.0;
        for (double v : ms) t += v;
        return t;
    }
    double& ms_of(Stage s) { return ms[static_cast<std::size_t>(s)]; }
    double ms_of(Stage s) const { return ms[static_cast<std::size_t>(s)]; }
    long long runs_of(Stage s) const { return runs[static_cast<std::size_t>(s)]; }
    void add(const StepProfile& other);
};

// Times one stage into a profile (or nothing, for a null profile) from construction to destruction.
class StageTimer {
public:
    StageTimer(StepProfile* profile, Stage stage)
        : profile_(profile), stage_(stage), start_(profile ? Clock::now() : Clock::time_point{}) {}
    ~StageTimer() {
        if (!profile_) return;
        const auto i = static_cast<std::size_t>(stage_);
        profile_->ms[i] += std::chrono::duration<double, std::milli>(Clock::now() - start_).count();
        ++profile_->runs[i];
    }
    StageTimer(const StageTimer&) = delete;
    StageTimer& operator=(const StageTimer&) = delete;

private:
    using Clock = std::chrono::steady_clock;
    StepProfile* profile_;
    Stage stage_;
    Clock::time_point start_;
};

}  // namespace clothsim
