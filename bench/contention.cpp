// clothsim-bench contention: the time per substep of each path that threads, with 0, 1 and 2 busy processes
// beside it (started and stopped here: each spins on a core, as a browser tab, a compiler or a game would),
// at solver.threads = 1, 2 and 0 (the default, which chooses while it runs). The three settings are timed in
// paired rounds (each round times them one after another, in a rotating order, so a change of load touches
// all alike); the table gives each setting's median and the ratios the default is judged by:
//   default / best   the default against the faster of 1 and 2 threads (target: at most 1.15)
//   two / one        2 threads forced against 1 thread forced (target with 2 busy processes: at most 2)
//   noise            a second 1-thread simulation timed in the same rounds against the first (the larger of
//                    the two ratios): how far two medians of the same work differ under this load, the floor
//                    below which a ratio above 1 says nothing
// Paths: `verlet` (bundled hanging: Verlet's fast solver, its tethers and the ground's blocks), `verlet-contact`
// (drape-sphere: the same with a sphere's contact on the team), `xpbd` (hanging with XPBD's grid form).
#include "contention.hpp"

#include "csv.hpp"

#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim::bench {
namespace {

using Clock = std::chrono::steady_clock;

// Busy processes: children that spin until killed (or until the benchmark dies). A child of a program with
// threads may only call async-signal-safe functions.
class BusyProcesses {
public:
    explicit BusyProcesses(int count) {
        const pid_t parent = getpid();
        for (int i = 0; i < count; ++i) {
            const pid_t pid = fork();
            if (pid < 0) throw std::runtime_error("fork failed: cannot start a busy process");
            if (pid == 0) {
                prctl(PR_SET_PDEATHSIG, SIGKILL);  // dies with the benchmark, even if it crashes
                if (getppid() != parent) _exit(0);
                volatile unsigned long spin = 0;
                for (;;) spin = spin + 1;
            }
            pids_.push_back(pid);
        }
    }
    ~BusyProcesses() {
        for (pid_t pid : pids_) kill(pid, SIGKILL);
        for (pid_t pid : pids_) waitpid(pid, nullptr, 0);
    }
    BusyProcesses(const BusyProcesses&) = delete;
    BusyProcesses& operator=(const BusyProcesses&) = delete;

private:
    std::vector<pid_t> pids_;
};

Scene path_scene(const std::string& path, int size) {
    Scene s;
    if (path == "verlet") {
        s = load_scene("hanging");
    } else if (path == "verlet-contact") {
        s = load_scene("drape-sphere");
    } else if (path == "xpbd") {
        s = load_scene("hanging");
        apply_override(s, "integration.integrator=xpbd");
    } else {
        throw std::invalid_argument("unknown path '" + path + "' (allowed: verlet, verlet-contact, xpbd)");
    }
    s.cloth.rows = s.cloth.cols = size;
    s.settings.solver.method = SolverMethod::Fast;
    s.settings.solver.sleep_speed = 0.0f;  // a sleeping cloth costs nothing: time the solver
    if (path != "xpbd") {  // Verlet at the resized grid's stable substep (XPBD is stable at any)
        const MassSpring probe = build_simulation(s);
        s.settings.integration.substeps = auto_substeps(stability_limit(probe), s.settings.integration.dt, 0.7f);
    }
    return s;
}

// Runs `substeps` substeps (or stops past `cap_seconds`) and returns the wall ms per substep.
double time_round(MassSpring& sim, long long substeps, double cap_seconds) {
    const auto start = Clock::now();
    long long done = 0;
    while (done < substeps) {
        sim.substep();
        ++done;
        if ((done & 3) == 0 && std::chrono::duration<double>(Clock::now() - start).count() > cap_seconds) break;
    }
    return 1e3 * std::chrono::duration<double>(Clock::now() - start).count() / static_cast<double>(done);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int run_contention(const ContentionOptions& options) {
    std::ofstream csv;
    if (!open_csv(options.csv, "path,size,busy,substeps_per_round,one_ms,two_ms,default_ms,default_threads,default_over_best,two_over_one,noise", csv)) return 2;
    std::printf("%-15s %5s %5s %10s %10s %12s %8s %15s %10s %8s\n", "path", "size", "busy", "1 thr ms", "2 thr ms",
                "default ms", "(uses)", "default/best", "two/one", "noise");
    constexpr std::array<int, 4> kThreads{1, 2, 0, 1};  // the last: the noise control
    try {
        for (const std::string& path : options.paths) {
            for (int size : options.sizes) {
                const Scene base = path_scene(path, size);
                // The round's length: min_seconds at one thread's speed, idle.
                long long substeps = 0;
                {
                    Scene s = base;
                    s.settings.solver.threads = 1;
                    MassSpring sim = build_simulation(s);
                    const double ms = time_round(sim, 20, 10.0);
                    substeps = std::max(8LL, static_cast<long long>(1e3 * options.min_seconds / ms));
                }
                for (int busy : options.loads) {
                    constexpr std::size_t kSims = kThreads.size();
                    std::array<MassSpring*, kSims> sims{};
                    std::vector<MassSpring> owned;
                    owned.reserve(kSims);
                    for (int t : kThreads) {
                        Scene s = base;
                        s.settings.solver.threads = t;
                        owned.push_back(build_simulation(s));
                    }
                    for (std::size_t k = 0; k < kSims; ++k) sims[k] = &owned[k];
                    BusyProcesses load(busy);
                    std::array<std::vector<double>, kSims> ms;
                    const double cap = 20.0 * options.min_seconds;
                    for (std::size_t k = 0; k < kSims; ++k) time_round(*sims[k], substeps, cap);  // warm: caches, the choice
                    for (int r = 0; r < options.rounds; ++r) {
                        for (std::size_t j = 0; j < kSims; ++j) {
                            const std::size_t k = (j + static_cast<std::size_t>(r)) % kSims;
                            ms[k].push_back(time_round(*sims[k], substeps, cap));
                        }
                    }
                    for (MassSpring* sim : sims) {
                        if (!sim->all_finite()) throw std::runtime_error(path + " at " + std::to_string(size) + " became non-finite");
                    }
                    const double one = median(ms[0]), two = median(ms[1]), automatic = median(ms[2]);
                    const double over_best = automatic / std::min(one, two), two_over_one = two / one;
                    const double again = median(ms[3]), noise = std::max(one / again, again / one);
                    const int uses = sims[2]->solver_threads();
                    std::printf("%-15s %5d %5d %10.3f %10.3f %12.3f %8d %15.2f %10.2f %8.2f\n", path.c_str(), size, busy,
                                one, two, automatic, uses, over_best, two_over_one, noise);
                    std::fflush(stdout);
                    if (csv.is_open()) {
                        csv << path << ',' << size << ',' << busy << ',' << substeps << ',' << one << ',' << two << ','
                            << automatic << ',' << uses << ',' << over_best << ',' << two_over_one << ',' << noise << '\n';
                    }
                }
            }
        }
    } catch (const std::exception& e) {
        std::cerr << "clothsim-bench contention: error: " << e.what() << "\n";
        return 2;
    }
    return 0;
}

}  // namespace clothsim::bench
