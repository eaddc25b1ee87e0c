// StepPlan: which stages a substep runs, chosen from the scene.
//
// MassSpring builds the plan when it is constructed and again whenever its settings change (MassSpring::apply
// replans at the point of change), never per particle. A stage that would do
// nothing is not run at all: a spring kind with stiffness 0 or no springs, zero wind, a disabled collider,
// no strain or speed limit. The contact model picks the colliders' stage: projection runs the colliders
// stage (every enabled shape in the list) after integration; penalty contact does not run it and adds a force
// stage ("contact") beside the wind instead. The fast solver compiles one variant per set of spring kinds, so a skipped kind
// costs no instruction in the hot loop (src/core/integrators/fast_solver.cpp). Gravity and damping are coefficients of
// the Verlet update's single multiply-add, not stages of their own: they cost the same whatever their value.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"
#include "clothsim/step_profile.hpp"

#include <array>
#include <string>
#include <vector>

namespace clothsim {

// How a substep advances the cloth.
enum class StepPath {
    FastVerlet,         // Verlet in the fast solver: springs and integration fused row by row
    TextbookVerlet,     // Verlet over the spring list, then over the particles (the oracle)
    VelocityIntegrator, // another integrator, through its row of the table (integrator.hpp)
};

struct StepPlan {
    StepPath path = StepPath::TextbookVerlet;
    std::array<bool, kSpringKindCount> springs{};  // a kind runs: it has springs and a non-zero stiffness
    bool wind = false;
    bool contact = false;  // penalty contact: a force stage (colliders.contact = penalty, a collider enabled)
    bool soft_clips = false;  // soft clips hold particles: a force stage
    bool colliders = false;  // the projection stage (projection contact, a collider enabled)
    bool solids = false;     // ... and a solid shape among them (not only planes): the blocks need whole boxes
    bool tethers = false;  // springs.tether_strain > 0 and the cloth has pins to tie to
    bool strain_limit = false;
    bool speed_limit = false;
    bool tear = false;       // springs.tear_strain > 0
    bool self_collision = false;  // collision.self
    bool may_sleep = false;  // sleep_speed > 0 and the air is still: nothing in the settings drives the cloth

    bool any_springs() const { return springs[0] || springs[1] || springs[2]; }
    // Forces besides the springs, gravity, damping and a grab, added on their own (add_external_forces).
    bool external_forces() const { return wind || contact || soft_clips; }
    // Bit k set when spring kind k runs: the fast solver's variant.
    unsigned spring_mask() const { return (springs[0] ? 1u : 0u) | (springs[1] ? 2u : 0u) | (springs[2] ? 4u : 0u); }
};

// `fast_solver` says whether the fast solver can run this topology.
// `tethers` says whether the cloth has any (it has pins).
StepPlan plan_step(const Topology& topology, const SimulationSettings& settings, bool fast_solver, bool tethers = false);

// Whether the wind stage exerts any force: air moving, or the uniform model's drag on a moving cloth.
bool wind_active(const ForceSettings& forces);

// One line per stage for the panel and the JSON: does it run under this plan as a timed stage of its own,
// is its work done (and timed) inside another stage, or is it skipped, and why. The reasons quote the
// setting that decided it.
enum class StageState { Runs, Fused, Skipped };
struct StageStatus {
    Stage stage;
    StageState state;
    std::string note;  // why it is skipped, where it is fused, or what it covers
    bool runs() const { return state == StageState::Runs; }
};
std::string_view state_name(StageState state);  // "runs", "fused", "skipped"
std::vector<StageStatus> describe(const StepPlan& plan, const Topology& topology, const SimulationSettings& settings);
// What the profile adds to a stage's note: for the colliders stage that ran, "sphere N of M, plane ... blocks
// tested" per kind (the broad phase's work); otherwise the status's own note. One wording for the panel, the text report and the JSON.
std::string profile_note(const StageStatus& status, const StepProfile& profile);

}  // namespace clothsim
