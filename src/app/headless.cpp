#include "headless.hpp"

#include "clothsim/export.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"
#include "clothsim/step_plan.hpp"

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
            if (const int c = collider_index(s.stage); c >= 0) {
                std::printf(" (%lld of %lld blocks tested)", p.blocks_tested[c], p.blocks_offered[c]);
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

}  // namespace

int run_headless(const Scene& scene, const HeadlessOptions& options) {
    MassSpring sim = build_simulation(scene);
    const double dt = scene.settings.integration.dt;
    const StabilityLimit limit = stability_limit(sim);
    if (options.auto_substeps > 0.0f) {
        const int chosen = auto_substeps(limit, scene.settings.integration.dt, options.auto_substeps);
        std::fprintf(stderr, "auto substeps: critical substep %.4g s (Gershgorin), %d substeps per step keep the "
                             "substep at %.2f of it\n",
                     limit.critical_substep, chosen, dt / chosen / limit.critical_substep);
        sim.settings().integration.substeps = chosen;
    }
    const long long steps = options.steps ? *options.steps
                            : options.duration ? std::llround(*options.duration / dt)
                                               : std::llround(1.0 / dt);

    // Check outputs before simulating, so a long run never fails at its end.
    std::unique_ptr<TrajectoryWriter> trajectory;
    if (!options.trajectory.empty()) {
        trajectory = std::make_unique<TrajectoryWriter>(options.trajectory);
        if (!trajectory->ok()) {
            std::cerr << "clothsim: error: " << trajectory->error() << "\n";
            return kExitBadInput;
        }
        trajectory->record(0, sim);
    }
    if (!options.obj.empty() && !parent_exists(options.obj)) {
        std::cerr << "clothsim: error: --obj " << options.obj << ": the directory does not exist\n";
        return kExitBadInput;
    }
    if (!options.obj.empty() && std::filesystem::is_directory(options.obj)) {
        std::cerr << "clothsim: error: --obj " << options.obj << ": is a directory, not a file name\n";
        return kExitBadInput;
    }

    const auto start = std::chrono::steady_clock::now();
    long long done = 0;
    bool finite = sim.all_finite();
    std::string guard_log;
    bool guard_ok = true;
    while (finite && guard_ok && done < steps) {
        if (options.guard) {
            std::string log;
            guard_ok = run_guarded(sim, 1, GuardSettings{}, log);
            if (!log.empty()) std::cerr << log;
            guard_log += log;
        } else {
            sim.run_steps(1);
        }
        ++done;
        finite = sim.all_finite();
        if (trajectory && (done % options.every == 0 || done == steps || !finite)) trajectory->record(done, sim);
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

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
    if (!finite || !guard_ok) {
        std::cerr << "clothsim: error: the simulation " << (finite ? "kept blowing up" : "became non-finite")
                  << " at t = " << sim.time() << " s (step " << done
                  << "); try a smaller integration.dt, more integration.substeps, softer springs, or --guard / "
                     "--auto-substeps\n";
        code = kExitNonFinite;
    }

    const Energy e = sim.energy();
    const StepProfile& profile = sim.profile();
    const std::vector<StageStatus> stages = describe(sim.plan(), sim.topology(), sim.settings());
    const auto finite_or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
    if (options.json) {
        nlohmann::json out = {
            {"scene", scene.name},
            {"particles", sim.particle_count()},
            {"springs", sim.spring_count()},
            {"steps", done},
            {"substeps_per_step", scene.settings.integration.substeps},
            {"dt", dt},
            {"simulated_seconds", sim.time()},
            {"wall_seconds", wall},
            {"finite", finite},
            {"critical_substep", std::isfinite(limit.critical_substep) ? nlohmann::json(limit.critical_substep)
                                                                        : nlohmann::json()},
            {"substep", sim.substep_length()},
            {"substeps_used", sim.settings().integration.substeps},
            {"guard_log", guard_log},
            {"kinetic_energy", finite_or_null(e.kinetic)},
            {"potential_energy", finite_or_null(e.potential())},
            {"total_energy", finite_or_null(e.total())},
            {"profile", profile_json(profile, stages, done, sim.asleep())},
        };
        std::cout << out.dump(2) << std::endl;
    } else {
        std::printf("scene %s: %zu particles, %zu springs\n", scene.name.c_str(), sim.particle_count(),
                    sim.spring_count());
        std::printf("ran %lld steps of %.6g s (%d substeps each): %.4g simulated s in %.3f wall s\n", done, dt,
                    sim.settings().integration.substeps, sim.time(), wall);
        std::printf("energy: kinetic %.6g J, potential %.6g J, total %.6g J; finite: %s\n", e.kinetic, e.potential(),
                    e.total(), finite ? "yes" : "no");
        print_profile(profile, stages, done, sim.asleep());
    }
    return code;
}

}  // namespace clothsim
