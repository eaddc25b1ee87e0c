// clothsim-bench realtime (README, "Bundled scenes in real time"): each bundled scene as the app runs it,
// headless: the Stepper with auto substeps at the app's safety and the guard on, the scene's other settings
// as in its file, for `duration` simulated seconds. Reported: wall seconds per simulated second (1.0 or
// less keeps up with real time), the median of interleaved repeats, per thread count.
#include "realtime.hpp"

#include "csv.hpp"

#include "clothsim/scene.hpp"
#include "clothsim/stepper.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace clothsim::bench {
namespace {

// The app's run policy (src/app/app.cpp, run_app): auto substeps at safety 0.5, the guard on.
RunPolicy app_policy() {
    RunPolicy policy;
    policy.auto_substeps = true;
    policy.safety = 0.5f;
    policy.guard = true;
    return policy;
}

struct Run {
    double wall_per_simulated = 0.0;
    int substeps = 0;
    bool ok = true;
};

Run run_scene(const Scene& scene, double duration) {
    MassSpring sim = build_simulation(scene);
    Stepper stepper(app_policy());
    const long long steps = std::max(1LL, static_cast<long long>(duration / scene.settings.integration.dt + 0.5));
    const auto start = std::chrono::steady_clock::now();
    const StepReport report = stepper.run(sim, steps);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return {wall / (double(steps) * scene.settings.integration.dt), sim.settings().integration.substeps,
            !report.guard_gave_up && sim.all_finite()};
}

}  // namespace

int run_realtime(const RealtimeOptions& options) {
    const std::vector<std::string> names = options.scenes.empty() ? bundled_scene_names() : options.scenes;
    // (scene, threads) -> the repeats' figures; the repeats go round every case before the next repeat, so a
    // passing load touches every case alike.
    std::map<std::pair<std::string, int>, std::vector<Run>> runs;
    for (int r = 0; r < options.repeats; ++r) {
        for (const std::string& name : names) {
            for (int threads : options.threads) {
                Scene scene = load_scene(name);
                scene.settings.solver.threads = threads;
                runs[{name, threads}].push_back(run_scene(scene, options.duration));
            }
        }
    }
    std::ofstream csv;
    if (!open_csv(options.csv, "scene,threads,substeps,wall_per_simulated_second,ok", csv)) return 2;
    std::printf("%-14s %8s %10s %16s\n", "scene", "threads", "substeps", "wall s / sim s");
    int failures = 0;
    for (const std::string& name : names) {
        for (int threads : options.threads) {
            std::vector<Run>& v = runs[{name, threads}];
            std::sort(v.begin(), v.end(), [](const Run& a, const Run& b) { return a.wall_per_simulated < b.wall_per_simulated; });
            const Run& median = v[v.size() / 2];
            const bool ok = std::all_of(v.begin(), v.end(), [](const Run& x) { return x.ok; });
            failures += ok ? 0 : 1;
            std::printf("%-14s %8d %10d %16.3f%s\n", name.c_str(), threads, median.substeps, median.wall_per_simulated,
                        ok ? "" : "  (blew up)");
            if (csv.is_open()) {
                csv << name << ',' << threads << ',' << median.substeps << ',' << median.wall_per_simulated << ','
                    << (ok ? 1 : 0) << '\n';
            }
        }
    }
    return failures == 0 ? 0 : 1;
}

}  // namespace clothsim::bench
