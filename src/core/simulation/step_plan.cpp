#include "clothsim/step_plan.hpp"

#include "clothsim/collider_motion.hpp"

#include <algorithm>
#include <array>
#include <initializer_list>
#include <utility>

namespace clothsim {

std::string_view stage_name(Stage stage) {
    switch (stage) {
        case Stage::Springs: return "springs";
        case Stage::Wind: return "wind";
        case Stage::Contact: return "contact";
        case Stage::SoftClips: return "soft clips";
        case Stage::Fast: return "fast solver";
        case Stage::Integrate: return "integrate";
        case Stage::BroadPhase: return "broad phase";
        case Stage::Colliders: return "colliders";
        case Stage::SelfCollision: return "self collision";
        case Stage::Tethers: return "tethers";
        case Stage::StrainLimit: return "strain limit";
        case Stage::Tear: return "tear";
        case Stage::SpeedLimit: return "speed limit";
        case Stage::Sleep: return "sleep check";
        case Stage::Count: break;
    }
    return "?";
}

void StepProfile::add(const StepProfile& other) {
    for (std::size_t i = 0; i < kStageCount; ++i) {
        ms[i] += other.ms[i];
        runs[i] += other.runs[i];
    }
    for (std::size_t i = 0; i < kColliderKindCount; ++i) {
        blocks_tested[i] += other.blocks_tested[i];
        blocks_offered[i] += other.blocks_offered[i];
    }
    self_tiles += other.self_tiles;
    self_tiles_active += other.self_tiles_active;
    self_contacts += other.self_contacts;
    substeps += other.substeps;
    slept_substeps += other.slept_substeps;
}

bool wind_active(const ForceSettings& forces) {
    return forces.wind != glm::vec3(0.0f) || forces.wind_model == WindModel::Uniform;
}

StepPlan plan_step(const Topology& topology, const SimulationSettings& settings, bool fast_solver, bool tethers) {
    StepPlan plan;
    if (integrator_info(settings.integration.integrator).substep) {  // not Verlet: its own substep
        plan.path = StepPath::VelocityIntegrator;
    } else {
        plan.path = fast_solver && settings.solver.method == SolverMethod::Fast ? StepPath::FastVerlet
                                                                                 : StepPath::TextbookVerlet;
    }
    const SpringSettings& springs = settings.springs;
    const bool k[kSpringKindCount] = {springs.structural != glm::vec2(0.0f), springs.shear != 0.0f,
                                      springs.bending != glm::vec2(0.0f)};
    for (int kind = 0; kind < kSpringKindCount; ++kind) {
        plan.springs[kind] = k[kind] && topology.spring_count_by_kind[kind] > 0;
    }
    plan.wind = wind_active(settings.forces);
    plan.soft_clips = !topology.clip_springs.empty();
    const ColliderSettings& c = settings.colliders;
    const bool any_enabled = std::any_of(c.shapes.begin(), c.shapes.end(), [](const Collider& s) { return s.enabled; });
    if (c.contact == ContactModel::Penalty) {
        plan.contact = any_enabled && c.thickness > 0.0f;  // no shell, no force (penalty_contact.hpp)
    } else {
        plan.colliders = any_enabled;
        plan.solids = std::any_of(c.shapes.begin(), c.shapes.end(),
                                  [](const Collider& s) { return s.enabled && !is_half_space(s); });
    }
    plan.tethers = settings.springs.tether_strain > 0.0f && tethers;
    plan.strain_limit = settings.springs.strain_limit > 0.0f;
    plan.speed_limit = settings.forces.max_speed > 0.0f;
    plan.tear = settings.springs.tear_strain > 0.0f;
    plan.self_collision = settings.collision.self;
    plan.may_sleep = settings.solver.sleep_speed > 0.0f && settings.forces.wind == glm::vec3(0.0f) && !colliders_move(c);
    return plan;
}

namespace {

// The enabled colliders' kinds, with a count where a kind repeats: "2 spheres, box, plane".
std::string enabled_shapes(const ColliderSettings& colliders) {
    std::array<int, kColliderKindCount> count{};
    for (const Collider& c : colliders.shapes) count[c.kind()] += c.enabled ? 1 : 0;
    std::string out;
    for (std::size_t kind = 0; kind < kColliderKindCount; ++kind) {
        if (count[kind] == 0) continue;
        out.append(out.empty() ? "" : ", ");
        if (count[kind] > 1) out.append(std::to_string(count[kind])).append(" ");
        out.append(collider_kind_names()[kind]);
        if (count[kind] > 1) out.append(collider_kind_names()[kind].ends_with('x') ? "es" : "s");
    }
    return out;
}

std::string spring_note(const StepPlan& plan, const Topology& topology) {
    std::string runs, skipped;
    for (int kind = 0; kind < kSpringKindCount; ++kind) {
        const std::string name = to_string(static_cast<SpringKind>(kind));
        if (plan.springs[kind]) {
            runs.append(runs.empty() ? "" : ", ").append(name);
        } else {
            skipped.append(skipped.empty() ? "" : "; ").append(name).append(
                topology.spring_count_by_kind[kind] == 0 ? ": no springs" : ": stiffness 0");
        }
    }
    if (runs.empty()) runs = "no spring kind";
    // A mesh cloth's constant-strain triangles carry its stretch and shear (its edge springs have weight 0).
    if (!topology.membranes.empty()) runs = "membrane triangles; " + runs;
    return skipped.empty() ? runs : runs.append(" (skipped ").append(skipped).append(")");
}

}  // namespace

std::string_view state_name(StageState state) {
    switch (state) {
        case StageState::Runs: return "runs";
        case StageState::Fused: return "fused";
        case StageState::Skipped: return "skipped";
    }
    return "?";
}

std::vector<StageStatus> describe(const StepPlan& plan, const Topology& topology, const SimulationSettings& settings) {
    using enum StageState;
    std::vector<StageStatus> out;
    const bool fast = plan.path == StepPath::FastVerlet;
    const bool velocity = plan.path == StepPath::VelocityIntegrator;
    const std::string springs = spring_note(plan, topology);
    auto when = [](bool runs, StageState otherwise) { return runs ? Runs : otherwise; };
    if (!plan.any_springs()) {
        out.push_back({Stage::Springs, Skipped, springs});
    } else if (fast) {
        out.push_back({Stage::Springs, Fused, "in the fast solver: " + springs});
    } else if (velocity) {
        out.push_back({Stage::Springs, Fused, "in the integrate stage (evaluated per force call): " + springs});
    } else {
        out.push_back({Stage::Springs, Runs, springs});
    }
    if (!plan.wind) {
        out.push_back({Stage::Wind, Skipped, "forces.wind is 0"});
    } else {
        out.push_back({Stage::Wind, velocity ? Fused : Runs, velocity ? "in the integrate stage" : ""});
    }
    const ColliderSettings& c = settings.colliders;
    const bool penalty = c.contact == ContactModel::Penalty;
    const bool any_enabled = std::any_of(c.shapes.begin(), c.shapes.end(), [](const Collider& s) { return s.enabled; });
    const std::string which = enabled_shapes(c);
    if (plan.contact) {
        out.push_back({Stage::Contact, velocity ? Fused : Runs,
                       velocity ? "in the integrate stage: " + which : "penalty forces of " + which});
    } else {
        out.push_back({Stage::Contact, Skipped,
                       !penalty ? "colliders.contact is projection"
                                : (any_enabled ? "colliders.thickness is 0" : "no collider is enabled")});
    }
    if (!plan.soft_clips) {
        out.push_back({Stage::SoftClips, Skipped, "no soft clip (pins.clip is rigid, or no pin has a radius)"});
    } else {
        out.push_back({Stage::SoftClips, velocity ? Fused : Runs,
                       std::to_string(topology.clip_springs.size()) + " particles held" + (velocity ? ", in the integrate stage" : "")});
    }
    out.push_back({Stage::Fast, when(fast, Skipped),
                   fast ? "springs, gravity, damping and the Verlet update, row by row"
                        : (velocity ? "the integrator is not verlet" : "solver.method is textbook (or the cloth is no grid)")});
    out.push_back({Stage::Integrate, fast ? Fused : Runs, fast ? "in the fast solver" : ""});
    const char* penalty_note = "colliders.contact is penalty (a force in the contact stage)";
    if (!plan.colliders) {
        out.push_back({Stage::BroadPhase, Skipped, penalty && any_enabled ? penalty_note : "no collider is enabled"});
    } else if (!settings.solver.broad_phase) {
        out.push_back({Stage::BroadPhase, Skipped, "solver.broad_phase is false"});
    } else {
        out.push_back({Stage::BroadPhase, Runs, fast ? "the cloth's box (the fast solver boxes the blocks)" : "boxes of the blocks and the cloth"});
    }
    const char* culled = settings.solver.broad_phase ? "blocks whose box meets it" : "every particle (broad phase off)";
    out.push_back({Stage::Colliders, when(plan.colliders, Skipped),
                   plan.colliders ? which + ": " + culled
                                  : (any_enabled ? penalty_note
                                                 : (c.shapes.empty() ? "colliders.shapes is empty" : "no collider is enabled"))});
    out.push_back({Stage::SelfCollision, when(plan.self_collision, Skipped),
                   plan.self_collision ? "tiles boxed; pairs within the thickness pushed apart" : "collision.self is false"});
    out.push_back({Stage::Tethers, when(plan.tethers, Skipped),
                   plan.tethers ? "" : (settings.springs.tether_strain > 0.0f ? "no pins to tie to" : "springs.tether_strain is 0")});
    out.push_back({Stage::StrainLimit, when(plan.strain_limit, Skipped), plan.strain_limit ? "" : "springs.strain_limit is 0"});
    out.push_back({Stage::SpeedLimit, when(plan.speed_limit, Skipped), plan.speed_limit ? "" : "forces.max_speed is 0"});
    out.push_back({Stage::Tear, when(plan.tear, Skipped),
                   plan.tear ? "once per step" : "springs.tear_strain is 0"});
    out.push_back({Stage::Sleep, when(plan.may_sleep, Skipped),
                   plan.may_sleep ? ""
                   : settings.solver.sleep_speed <= 0.0f    ? "solver.sleep_speed is 0"
                   : colliders_move(settings.colliders)     ? "a moving collider keeps it awake"
                                                            : "forces.wind keeps it awake"});
    return out;
}

std::string profile_note(const StageStatus& status, const StepProfile& profile) {
    if (status.stage == Stage::SelfCollision && status.runs() && profile.self_tiles > 0) {
        return std::to_string(profile.self_tiles_active) + " of " + std::to_string(profile.self_tiles) +
               " tiles in the narrow phase, " + std::to_string(profile.self_contacts) + " contacts";
    }
    if (status.stage != Stage::Colliders || !status.runs()) return status.note;
    std::string note;
    for (std::size_t kind = 0; kind < kColliderKindCount; ++kind) {
        if (profile.blocks_offered[kind] == 0) continue;
        note.append(note.empty() ? "" : ", ")
            .append(collider_kind_names()[kind])
            .append(" ")
            .append(std::to_string(profile.blocks_tested[kind]))
            .append(" of ")
            .append(std::to_string(profile.blocks_offered[kind]));
    }
    return note.empty() ? status.note : note + " blocks tested";
}

}  // namespace clothsim
