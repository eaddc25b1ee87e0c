#include "headless.hpp"

#include "clothsim/export.hpp"
#include "clothsim/intersections.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/settle.hpp"
#include "clothsim/stability.hpp"
#include "clothsim/step_plan.hpp"
#include "clothsim/stepper.hpp"
#include "clothsim/strain.hpp"

#include "clothsim/drape.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {
namespace {

constexpr double kSettleSeconds = 30.0;  // a settle's time limit when --duration and --steps are not given

bool parent_exists(const std::string& path) {
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    return parent.empty() || std::filesystem::is_directory(parent);
}


// The run's step profile: every stage of the plan with its time (total and per step) or why it was skipped.
nlohmann::json profile_json(const StepProfile& p, const std::vector<StageStatus>& stages, long long steps, bool asleep) {
    nlohmann::json list = nlohmann::json::array();
    for (const StageStatus& s : stages) {
        const std::size_t i = static_cast<std::size_t>(s.stage);
        nlohmann::json stage = {{"stage", std::string(stage_name(s.stage))},
                                {"state", std::string(state_name(s.state))},
                                {"ms", p.ms[i]},
                                {"ms_per_step", steps > 0 ? p.ms[i] / double(steps) : 0.0},
                                {"substeps_run", p.runs[i]},
                                {"note", s.note}};
        if (s.stage == Stage::Colliders) {
            // Per kind (collider.hpp), for the kinds the scene holds.
            nlohmann::json tested = nlohmann::json::object(), offered = nlohmann::json::object();
            for (std::size_t kind = 0; kind < kColliderKindCount; ++kind) {
                if (p.blocks_offered[kind] == 0) continue;
                tested[std::string(collider_kind_names()[kind])] = p.blocks_tested[kind];
                offered[std::string(collider_kind_names()[kind])] = p.blocks_offered[kind];
            }
            stage["blocks_tested"] = tested;
            stage["blocks_offered"] = offered;
        }
        if (s.stage == Stage::SelfCollision) {
            stage["tiles"] = p.self_tiles;
            stage["tiles_in_narrow_phase"] = p.self_tiles_active;
            stage["contacts"] = p.self_contacts;
        }
        list.push_back(stage);
    }
    return {{"stages", list},
            {"total_ms", p.total_ms()},
            {"substeps", p.substeps},
            {"slept_substeps", p.slept_substeps},
            {"asleep_at_end", asleep}};
}

void print_profile(const StepProfile& p, const std::vector<StageStatus>& stages, long long steps, bool asleep) {
    std::printf("stages, ms per step:");
    std::string skipped, fused;
    for (const StageStatus& s : stages) {
        const std::size_t i = static_cast<std::size_t>(s.stage);
        if (s.runs()) {
            std::printf(" %s %.4f", std::string(stage_name(s.stage)).c_str(), steps > 0 ? p.ms[i] / double(steps) : 0.0);
            if (s.stage == Stage::Colliders || s.stage == Stage::SelfCollision) {
                std::printf(" (%s)", profile_note(s, p).c_str());
            }
            std::printf(";");
        } else {
            std::string& list = s.state == StageState::Skipped ? skipped : fused;
            list.append(list.empty() ? "" : "; ").append(stage_name(s.stage)).append(" (").append(s.note).append(")");
        }
    }
    std::printf("\nfused: %s\nskipped: %s\n", fused.c_str(), skipped.c_str());
    if (p.slept_substeps > 0 || asleep) {
        std::printf("asleep for %lld of %lld substeps%s\n", p.slept_substeps, p.slept_substeps + p.substeps,
                    asleep ? " (asleep at the end)" : "");
    }
}


// Checks the output paths before simulating, so a long run never fails at its end; opens the trajectory.
// Returns an error message, or "".
std::string open_outputs(const HeadlessOptions& options, const MassSpring& sim,
                         std::unique_ptr<TrajectoryWriter>& trajectory) {
    if (!options.trajectory.empty()) {
        trajectory = std::make_unique<TrajectoryWriter>(options.trajectory);
        if (!trajectory->ok()) return trajectory->error();
        trajectory->record(0, sim);
    }
    if (!options.obj.empty() && !parent_exists(options.obj)) {
        return "--obj " + options.obj + ": the directory does not exist";
    }
    if (!options.obj.empty() && std::filesystem::is_directory(options.obj)) {
        return "--obj " + options.obj + ": is a directory, not a file name";
    }
    return "";
}

// What a run did, for the report.
struct RunOutcome {
    long long steps = 0;
    bool finite = true;
    BlowUp blow_up = BlowUp::None;  // why the last step failed the guard's check (without --guard)
    bool guard_ok = true;           // with --guard: false when it ran out of retries
    std::string guard_log;
    double wall_seconds = 0.0;

    bool blew_up() const { return blow_up != BlowUp::None || !guard_ok; }
    const char* cause() const { return guard_ok ? blow_up_name(blow_up) : "the guard gave up"; }
};

// The run itself: one step at a time through the stepper (so the trajectory can record any step), until
// `steps` or a blow-up. Without --guard each step gets the guard's check (check_step), so a cloth the guard
// would roll back stops the run there, finite or not: a blow-up held finite by tethers (1e9 J and more) is
// still a blow-up. With --guard the guard itself checks and retries.
RunOutcome simulate(MassSpring& sim, Stepper& stepper, long long steps, const HeadlessOptions& options,
                    TrajectoryWriter* trajectory, Settler* settler) {
    RunOutcome run;
    const auto start = std::chrono::steady_clock::now();
    const GuardSettings& guard = stepper.policy().guard_settings;
    run.finite = sim.all_finite();
    if (!run.finite) run.blow_up = BlowUp::NonFinite;
    double energy = run.finite ? sim.energy().total() : 0.0;  // J at the start of the next step
    while (!run.blew_up() && run.steps < steps) {
        const StepReport report = stepper.run(sim, 1);
        if (!report.guard_log.empty()) std::cerr << report.guard_log;
        run.guard_log += report.guard_log;
        run.guard_ok = !report.guard_gave_up;
        ++run.steps;
        run.finite = sim.all_finite();
        if (!options.guard) {
            const StepCheck check = check_step(sim, energy, guard);
            run.blow_up = check.blow_up;
            energy = check.energy;
        } else if (!run.finite) {
            run.blow_up = BlowUp::NonFinite;
        }
        const bool settled = settler && !run.blew_up() && settler->after_step(sim);
        if (trajectory && (run.steps % options.every == 0 || run.steps == steps || run.blew_up() || settled)) {
            trajectory->record(run.steps, sim);
        }
        if (settled) break;
    }
    run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return run;
}

// What sets the critical substep (StabilityLimit::bound, and the wind's limit folded into it), for messages.
const char* bound_source(const StabilityLimit& limit) {
    if (limit.wind_substep <= limit.critical_substep) return "the wind's drag";
    switch (limit.bound) {
        case StabilityBound::Springs: return "the springs";
        case StabilityBound::Damping: return "the damping (c h < 2)";
        case StabilityBound::Contact: return "penalty contact";
        case StabilityBound::SoftClips: return "the soft clips";
    }
    return "the springs";
}

// The substep in force against the safe (Gershgorin) stability bound, critical_substep of stability.hpp, in
// words ("substep 0.0167 s is above the stability bound 0.000231 s of the springs"), with what brings it within:
// the substeps of auto_substeps at safety 1, ceil(dt / bound), or, where even kMaxSubsteps is not enough, a
// smaller dt. An integrator stable at any substep (implicit Euler without contact or clips) has no bound, nor
// has a cloth without springs.
struct SubstepCheck {
    bool above = false;
    std::string text;            // where the substep stands
    std::string fix;             // what brings it within the bound ("" when it is within)
    bool substeps_fix = false;   // `fix` is a number of substeps, which --auto-substeps would choose too
};
SubstepCheck check_substep(const MassSpring& sim, const StabilityLimit& limit) {
    SubstepCheck check;
    const double substep = sim.substep_length();
    char text[200];
    if (limit.unconditionally_stable || !std::isfinite(limit.critical_substep)) {
        std::snprintf(text, sizeof text, "substep %.3g s has no stability bound here (integration.integrator = %s)",
                      substep,
                      std::string(integrator_names()[static_cast<int>(sim.settings().integration.integrator)]).c_str());
        check.text = text;
        return check;
    }
    check.above = substep > limit.critical_substep;
    std::snprintf(text, sizeof text, "substep %.3g s is %s the stability bound %.3g s of %s", substep,
                  check.above ? "above" : "within", limit.critical_substep, bound_source(limit));
    check.text = text;
    if (check.above) {
        const float dt = sim.settings().integration.dt;
        const int needed = auto_substeps(limit, dt, 1.0f);
        check.substeps_fix = double(dt) / needed <= limit.critical_substep;
        if (check.substeps_fix) {
            check.fix = "integration.substeps >= " + std::to_string(needed);
        } else {
            std::snprintf(text, sizeof text, "integration.dt <= %.3g s with integration.substeps = %d",
                          kMaxSubsteps * limit.critical_substep, kMaxSubsteps);
            check.fix = text;
        }
    }
    return check;
}

// Closes the outputs (trajectory, OBJ) and says what failed; returns the exit code.
int finish(const HeadlessOptions& options, const MassSpring& sim, const RunOutcome& run, const StabilityLimit& limit,
           TrajectoryWriter* trajectory) {
    int code = kExitOk;
    if (trajectory && !trajectory->finish()) {
        std::cerr << "clothsim: error: " << trajectory->error() << "\n";
        code = kExitBadInput;
    }
    if (!options.obj.empty()) {
        std::string error;
        if (!write_obj(sim, options.obj, error, options.obj_colliders)) {
            std::cerr << "clothsim: error: " << error << "\n";
            code = kExitBadInput;
        }
    }
    if (run.blew_up()) {
        // One line: when, why, and the substep against the bound known before stepping (the limit of the cloth
        // as it started: its wind bound reads the cloth's area, which a blown-up cloth no longer has).
        const SubstepCheck substep = check_substep(sim, limit);
        const std::string advice =
            !substep.above ? "try more integration.substeps, a smaller integration.dt, softer springs, or --guard"
                           : "use " + substep.fix + (substep.substeps_fix ? " or --auto-substeps" : "");
        std::fprintf(stderr, "clothsim: error: the simulation blew up at t = %.4g s (step %lld: %s): %s; %s\n",
                     sim.time(), run.steps, run.cause(), substep.text.c_str(), advice.c_str());
        code = kExitBlowUp;
    }
    return code;
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// One JSON object: the scene, what ran (the substeps in force at the end: auto substeps' choice or the
// guard's), energies, the largest membrane strain and the step profile.
void print_json(const Scene& scene, const MassSpring& sim, const RunOutcome& run, const StabilityLimit& limit,
                const Settler* settler) {
    const Energy e = sim.energy();
    const std::vector<StageStatus> stages = describe(sim.plan(), sim.topology(), sim.settings());
    nlohmann::json out = {
        {"scene", scene.name},
        {"particles", sim.particle_count()},
        {"springs", sim.spring_count()},
        {"bends", sim.bend_count()},
        {"steps", run.steps},
        {"substeps_per_step", sim.settings().integration.substeps},
        {"dt", sim.settings().integration.dt},
        {"simulated_seconds", sim.time()},
        {"wall_seconds", run.wall_seconds},
        {"finite", run.finite},
        {"blew_up", run.blew_up()},
        {"blow_up", run.blew_up() ? nlohmann::json(run.cause()) : nlohmann::json()},
        {"critical_substep", finite_or_null(limit.critical_substep)},
        {"critical_substep_at_strain", finite_or_null(stability_limit(sim).at_strain_substep)},  // at the end
        {"substep", sim.substep_length()},
        {"guard_log", run.guard_log},
        {"kinetic_energy", finite_or_null(e.kinetic)},
        {"potential_energy", finite_or_null(e.potential())},
        {"total_energy", finite_or_null(e.total())},
        {"max_strain", finite_or_null(max_membrane_strain(sim.topology(), sim.state().position))},
        {"tethers", sim.tether_count()},
        {"tethers_at_limit", sim.plan().tethers ? sim.tethers_at_limit() : 0},
        {"broken_springs", sim.broken_springs()},
        {"self_intersections", intersecting_triangle_pairs(sim.topology(), sim.positions())},
        {"profile", profile_json(sim.profile(), stages, run.steps, sim.asleep())},
    };
    // Which solver ran and, for an iterative one, how far its last solve got.
    const Integrator integrator = sim.settings().integration.integrator;
    nlohmann::json solver = {
        {"integrator", integrator_names()[static_cast<int>(integrator)]},
        {"path", sim.last_step_fast() ? "fast" : sim.plan().path == StepPath::TextbookVerlet ? "textbook" : "velocity integrator"},
        {"threads", sim.solver_threads()},
    };
    if (reports_solve(integrator)) {
        // Last substep (MassSpring::last_solver_residual): CG (implicit-euler), quasi-Newton (projective) or
        // constraint (xpbd) iterations and relative residual.
        solver["iterations"] = sim.last_solver_iterations();
        solver["residual"] = finite_or_null(sim.last_solver_residual());
    }
    out["solver"] = solver;
    if (settler) {
        out["settle"] = {
            {"settled", settler->settled()},
            {"residual", finite_or_null(settler->residual().value)},
            {"particle", settler->residual().particle},
            {"tolerance", settler->options().tolerance},
            {"velocity_resets", settler->resets()},
            {"damped_from", settler->damping() ? nlohmann::json(settler->damping_since()) : nlohmann::json(nullptr)},
            {"damping_rate", settler->damping_rate()},
        };
    }
    // A disc (a grid's, or a mesh cloth) on the cylinder is a Cusick drape test (drape.hpp): its coefficient and
    // folds.
    const CylinderCollider* support = nullptr;
    for (const Collider& c : sim.settings().colliders.shapes) {
        if (!support && c.enabled) support = std::get_if<CylinderCollider>(&c.shape);
    }
    if ((scene.cloth.shape == ClothShape::Disc || scene.cloth.is_mesh()) && support) {
        const DrapeFigures drape = measure_drape(sim, glm::dvec3(support->center), support->radius);
        out["drape_coefficient"] = finite_or_null(drape.drape_coefficient);
        out["folds"] = drape.folds;
        out["drape_outline"] = {drape.outline_min, drape.outline_max};
    }
    std::cout << out.dump(2) << std::endl;
}

void print_text(const Scene& scene, const MassSpring& sim, const RunOutcome& run, const Settler* settler) {
    const Energy e = sim.energy();
    std::printf("scene %s: %zu particles, %zu springs\n", scene.name.c_str(), sim.particle_count(), sim.spring_count());
    std::printf("ran %lld steps of %.6g s (%d substeps each): %.4g simulated s in %.3f wall s\n", run.steps,
                sim.settings().integration.dt, sim.settings().integration.substeps, sim.time(), run.wall_seconds);
    std::printf("energy: kinetic %.6g J, potential %.6g J, total %.6g J; finite: %s; blew up: %s%s%s\n", e.kinetic,
                e.potential(), e.total(), run.finite ? "yes" : "no", run.blew_up() ? "yes (" : "no",
                run.cause(), run.blew_up() ? ")" : "");
    if (settler) {
        std::printf("%s after %.4g simulated s: residual %.3g (tolerance %.3g) at particle %zu, %d velocity resets",
                    settler->settled() ? "settled" : "not settled", sim.time(), settler->residual().value,
                    settler->options().tolerance, settler->residual().particle, settler->resets());
        if (settler->damping()) {
            std::printf(", damped from t = %.4g s (last at %.3g/s)", settler->damping_since(), settler->damping_rate());
        }
        std::printf("\n");
    }
    print_profile(sim.profile(), describe(sim.plan(), sim.topology(), sim.settings()), run.steps, sim.asleep());
}

}  // namespace

int run_headless(const Scene& scene, const HeadlessOptions& options) {
    MassSpring sim = build_simulation(scene);
    RunPolicy policy;
    policy.auto_substeps = options.auto_substeps > 0.0f;
    policy.safety = options.auto_substeps;
    policy.guard = options.guard;
    Stepper stepper(policy);
    const StabilityLimit limit = stepper.limit(sim);
    const double dt = scene.settings.integration.dt;
    if (policy.auto_substeps) {
        const int chosen = stepper.choose_substeps(sim);
        std::fprintf(stderr, "auto substeps: critical substep %.4g s (Gershgorin), %d substeps per step keep the "
                             "substep at %.2f of it\n",
                     limit.critical_substep, chosen, dt / chosen / limit.critical_substep);
    }
    // Before stepping: a substep above the safe bound is not known to be stable (the measured limit lies within
    // 1.6x of it, docs/STABILITY.md) and a blow-up is likely, which only --guard recovers from; said once, here,
    // so a long run does not start silently toward its failure.
    if (const SubstepCheck substep = check_substep(sim, limit); substep.above) {
        std::cerr << "clothsim: warning: " << substep.text << " (" << substep.fix << " needed); expect a blow-up"
                  << (policy.guard ? ", which --guard will retry with more substeps" : "") << "\n";
    }
    // A settle runs until it settles, up to 30 simulated s unless told.
    const long long steps = options.steps ? *options.steps
                            : options.duration ? std::llround(*options.duration / dt)
                                               : std::llround((options.settle ? kSettleSeconds : 1.0) / dt);
    std::optional<Settler> settler;
    if (options.settle) settler.emplace(SettleOptions{.tolerance = options.settle_tolerance});
    std::unique_ptr<TrajectoryWriter> trajectory;
    if (const std::string error = open_outputs(options, sim, trajectory); !error.empty()) {
        std::cerr << "clothsim: error: " << error << "\n";
        return kExitBadInput;
    }
    const RunOutcome run = simulate(sim, stepper, steps, options, trajectory.get(), settler ? &*settler : nullptr);
    int code = finish(options, sim, run, limit, trajectory.get());
    if (settler && !settler->settled() && code == kExitOk) {
        std::fprintf(stderr, "clothsim: not settled after %.4g simulated s: residual %.3g at particle %zu, tolerance %.3g "
                             "(a longer --duration, or a larger --settle-tolerance)\n",
                     sim.time(), settler->residual().value, settler->residual().particle, settler->options().tolerance);
        code = kExitNotSettled;
    }
    if (options.json) print_json(scene, sim, run, limit, settler ? &*settler : nullptr);
    else print_text(scene, sim, run, settler ? &*settler : nullptr);
    return code;
}

}  // namespace clothsim
