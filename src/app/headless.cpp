#include "headless.hpp"

#include "clothsim/export.hpp"
#include "clothsim/intersections.hpp"
#include "clothsim/scene.hpp"
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
#include <string>
#include <vector>

namespace clothsim {
namespace {

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
        if (const int c = collider_index(s.stage); c >= 0) {
            stage["blocks_tested"] = p.blocks_tested[c];
            stage["blocks_offered"] = p.blocks_offered[c];
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
            if (collider_index(s.stage) >= 0 || s.stage == Stage::SelfCollision) {
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
    bool guard_ok = true;
    std::string guard_log;
    double wall_seconds = 0.0;
};

// The run itself: one step at a time through the stepper (so the trajectory can record any step), until
// `steps`, a non-finite cloth, or a guard that gave up.
RunOutcome simulate(MassSpring& sim, Stepper& stepper, long long steps, const HeadlessOptions& options,
                    TrajectoryWriter* trajectory) {
    RunOutcome run;
    const auto start = std::chrono::steady_clock::now();
    run.finite = sim.all_finite();
    while (run.finite && run.guard_ok && run.steps < steps) {
        const StepReport report = stepper.run(sim, 1);
        if (!report.guard_log.empty()) std::cerr << report.guard_log;
        run.guard_log += report.guard_log;
        run.guard_ok = !report.guard_gave_up;
        ++run.steps;
        run.finite = sim.all_finite();
        if (trajectory && (run.steps % options.every == 0 || run.steps == steps || !run.finite)) {
            trajectory->record(run.steps, sim);
        }
    }
    run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return run;
}

// Closes the outputs (trajectory, OBJ) and says what failed; returns the exit code.
int finish(const HeadlessOptions& options, const MassSpring& sim, const RunOutcome& run, TrajectoryWriter* trajectory) {
    int code = kExitOk;
    if (trajectory && !trajectory->finish()) {
        std::cerr << "clothsim: error: " << trajectory->error() << "\n";
        code = kExitBadInput;
    }
    if (!options.obj.empty()) {
        std::string error;
        if (!write_obj(sim, options.obj, error)) {
            std::cerr << "clothsim: error: " << error << "\n";
            code = kExitBadInput;
        }
    }
    if (!run.finite || !run.guard_ok) {
        std::cerr << "clothsim: error: the simulation " << (run.finite ? "kept blowing up" : "became non-finite")
                  << " at t = " << sim.time() << " s (step " << run.steps
                  << "); try a smaller integration.dt, more integration.substeps, softer springs, or --guard / "
                     "--auto-substeps\n";
        code = kExitNonFinite;
    }
    return code;
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// One JSON object: the scene, what ran (the substeps in force at the end: auto substeps' choice or the
// guard's), energies, the largest membrane strain and the step profile.
void print_json(const Scene& scene, const MassSpring& sim, const RunOutcome& run, const StabilityLimit& limit) {
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
        {"critical_substep", finite_or_null(limit.critical_substep)},
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
        {"path", sim.last_step_fast() ? "fast" : sim.plan().path == StepPath::Textbook ? "textbook" : "velocity integrator"},
        {"threads", sim.solver_threads()},
    };
    if (reports_solve(integrator)) {
        // Last substep (MassSpring::last_solver_residual): CG (implicit-euler), quasi-Newton (projective) or
        // constraint (xpbd) iterations and relative residual.
        solver["iterations"] = sim.last_solver_iterations();
        solver["residual"] = finite_or_null(sim.last_solver_residual());
    }
    out["solver"] = solver;
    // A disc on the cylinder is a Cusick drape test (drape.hpp): its coefficient and folds.
    const CylinderCollider& support = sim.settings().colliders.cylinder;
    if (scene.cloth.shape == ClothShape::Disc && support.enabled) {
        const DrapeFigures drape = measure_drape(sim, glm::dvec3(support.center), support.radius);
        out["drape_coefficient"] = finite_or_null(drape.drape_coefficient);
        out["folds"] = drape.folds;
        out["drape_outline"] = {drape.outline_min, drape.outline_max};
    }
    std::cout << out.dump(2) << std::endl;
}

void print_text(const Scene& scene, const MassSpring& sim, const RunOutcome& run) {
    const Energy e = sim.energy();
    std::printf("scene %s: %zu particles, %zu springs\n", scene.name.c_str(), sim.particle_count(), sim.spring_count());
    std::printf("ran %lld steps of %.6g s (%d substeps each): %.4g simulated s in %.3f wall s\n", run.steps,
                sim.settings().integration.dt, sim.settings().integration.substeps, sim.time(), run.wall_seconds);
    std::printf("energy: kinetic %.6g J, potential %.6g J, total %.6g J; finite: %s\n", e.kinetic, e.potential(),
                e.total(), run.finite ? "yes" : "no");
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
    const long long steps = options.steps ? *options.steps
                            : options.duration ? std::llround(*options.duration / dt)
                                               : std::llround(1.0 / dt);
    std::unique_ptr<TrajectoryWriter> trajectory;
    if (const std::string error = open_outputs(options, sim, trajectory); !error.empty()) {
        std::cerr << "clothsim: error: " << error << "\n";
        return kExitBadInput;
    }
    const RunOutcome run = simulate(sim, stepper, steps, options, trajectory.get());
    const int code = finish(options, sim, run, trajectory.get());
    if (options.json) print_json(scene, sim, run, limit);
    else print_text(scene, sim, run);
    return code;
}

}  // namespace clothsim
