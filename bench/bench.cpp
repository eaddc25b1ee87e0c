// clothsim-bench: throughput of the fast solver against the textbook one, and the frame budget.
//
// Table-driven: every case is a scene built by the same builder as the app (build_simulation), timed as the
// median of several repetitions, written as CSV (and JSON). See docs/PERFORMANCE.md for the results.
#include "textbook_aos.hpp"
#include "contention.hpp"
#include "fma_peak.hpp"
#include "realtime.hpp"
#include "skipping.hpp"
#include "stability_sweep.hpp"
#include "stiff_precision.hpp"
#include "substep_sweep.hpp"
#include "work_precision.hpp"

#include "clothsim/normals.hpp"
#include "clothsim/stability.hpp"
#include "clothsim/scene.hpp"

#include "per_spring_scenes.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace clothsim;
using Clock = std::chrono::steady_clock;

// The base scene resized. A bundled scene runs in its per-spring form (tests/fixtures/per_spring_scenes.hpp), the workload
// the recorded figures measured, so they stay comparable after the scenes moved to [material].
// Its substeps are set to 0.7 of the critical substep on the resized grid (as --auto-substeps 0.7 does; the
// timed cost of one substep does not depend on their number): at the file's own substeps, `hanging` resized
// to 128 x 128 or more becomes non-finite in its first step, and a benchmark would time NaN arithmetic.
Scene grid_scene(const std::string& base, int size, SolverMethod method, int threads) {
    Scene s = load_per_spring(base);
    s.cloth.rows = size;
    s.cloth.cols = size;
    s.settings.solver.method = method;
    s.settings.solver.threads = threads;
    const MassSpring probe = build_simulation(s);
    s.settings.integration.substeps = auto_substeps(stability_limit(probe), s.settings.integration.dt, 0.7f);
    s.settings.solver.sleep_speed = 0.0f;  // a sleeping cloth's substep costs nothing: time the solver
    return s;
}

// A timed cloth must still be a cloth: NaN arithmetic is no measure of the solver.
void require_finite(const MassSpring& sim, const std::string& scene, int size) {
    if (!sim.all_finite()) {
        throw std::runtime_error(scene + " at " + std::to_string(size) + " x " + std::to_string(size) +
                                 " became non-finite while it was timed");
    }
}

// Median wall time of one call of `work`, over `repeats` timed runs each at least `min_seconds` long.
template <class Work>
double median_seconds(Work&& work, int repeats, double min_seconds) {
    long long calls = 1;
    for (;;) {  // calibrate so one repetition is long enough to time
        const auto t0 = Clock::now();
        for (long long i = 0; i < calls; ++i) work();
        const double t = std::chrono::duration<double>(Clock::now() - t0).count();
        if (t >= min_seconds) break;
        calls = std::max(calls * 2, static_cast<long long>(calls * min_seconds / std::max(t, 1e-9)));
    }
    std::vector<double> samples;
    for (int r = 0; r < repeats; ++r) {
        const auto t0 = Clock::now();
        for (long long i = 0; i < calls; ++i) work();
        samples.push_back(std::chrono::duration<double>(Clock::now() - t0).count() / static_cast<double>(calls));
    }
    std::sort(samples.begin(), samples.end());
    return samples[samples.size() / 2];
}

// Bytes of per-particle simulation state: position and motion (6 doubles), mass, inverse mass (floats) and
// the pin flag, plus the fast solver's six rest lengths; the array-of-structs particle as laid out in memory.
double state_bytes_per_particle(const std::string& method) {
    if (method == "textbook-aos") return sizeof(bench::TextbookAos::Particle);
    const double common = 6 * 8 + 4 + 4 + 1;
    return method == "fast" ? common + 6 * 4 : common;
}

struct Row {
    int size = 0;
    std::size_t particles = 0, springs = 0;
    std::string method;
    int threads = 1;
    double seconds_per_step = 0;
    double speedup = 0;      // against the textbook solver in MassSpring (SoA, spring list)
    double speedup_aos = 0;  // against the array-of-structs textbook of the performance notes
};

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"clothsim-bench: solver throughput and frame budget"};
    std::vector<int> sizes{32, 64, 128, 256, 512};
    std::vector<int> thread_counts{1, 2};
    std::string scene = "hanging", csv_path, json_path, kernel_name;
    int repeats = 7;
    double min_seconds = 0.05;
    double budget_ms = 8.0;
    app.add_option("--sizes", sizes, "Grid sizes (particles per side)")->delimiter(',');
    app.add_option("--threads", thread_counts, "Thread counts for the fast solver")->delimiter(',');
    app.add_option("--scene", scene, "Base scene (its cloth is resized; a bundled one in its per-spring form)")
        ->capture_default_str();
    app.add_option("--repeats", repeats, "Timed repetitions per case (the median is reported)")->capture_default_str();
    app.add_option("--min-seconds", min_seconds, "Minimum length of one repetition")->capture_default_str();
    app.add_option("--budget-ms", budget_ms, "Frame budget for the substeps-per-frame figure")->capture_default_str();
    app.add_option("--csv", csv_path, "Write the table as CSV");
    app.add_option("--json", json_path, "Write the table and the frame budget as JSON");
    app.add_option("--kernel", kernel_name,
                   "The fast solver's kernel: avx512, avx2 or generic (default: the best this CPU runs)");
    bench::WorkPrecisionOptions wp;
    CLI::App* work_precision =
        app.add_subcommand("work-precision", "Run time against error for every integrator (docs/ACCURACY.md)");
    work_precision->add_option("--scene,--scenes", wp.scenes, "Study scenes: smooth, drape, flag")->delimiter(',');
    work_precision->add_option("--integrators", wp.integrators, "Integrators to sweep")->delimiter(',');
    work_precision->add_option("--T", wp.duration, "Simulated seconds per run")->check(CLI::PositiveNumber);
    work_precision->add_option("--levels", wp.levels, "Step sizes per integrator (halving)")->check(CLI::Range(1, 20));
    work_precision->add_option("--repeats", wp.repeats, "Timed repetitions (median)")->check(CLI::Range(1, 50));
    work_precision->add_option("--csv", wp.csv, "Write the sweep as CSV");
    work_precision->add_option("--plots", wp.plot_dir, "Write accuracy-SCENE.png here (needs --csv; gnuplot)");
    bench::StiffPrecisionOptions sp;
    CLI::App* stiff_precision = app.add_subcommand(
        "stiff-precision",
        "Run time against error on stiff-hanging (cotton at its measured stretch) for every integrator, one thread "
        "(docs/ACCURACY.md)");
    stiff_precision->add_option("--sizes", sp.sizes, "Particles per side")->delimiter(',')->check(CLI::Range(2, 1024));
    stiff_precision->add_option("--integrators", sp.integrators, "Integrators to sweep")->delimiter(',');
    stiff_precision->add_option("--repeats", sp.repeats, "Timed repetitions (median)")->check(CLI::Range(1, 50));
    stiff_precision->add_option("--reference-factor", sp.reference_factor,
                                "The reference: Verlet at this many times the stable substeps")
        ->check(CLI::Range(4, 64));
    stiff_precision->add_option("--set", sp.overrides,
                                "KEY=VALUE scene field for every integrator but Verlet (e.g. integration.iterations=30)");
    stiff_precision->add_option("--min-substeps", sp.min_substeps,
                                "Integrators that are not explicit (implicit-euler, xpbd, projective): start their doubling sweep here")
        ->check(CLI::Range(1, kMaxSubsteps));
    stiff_precision->add_option("--max-substeps", sp.max_substeps,
                                "Integrators that are not explicit: MIN, 2 MIN, 4 MIN, ... up to this")
        ->check(CLI::Range(1, kMaxSubsteps));
    stiff_precision->add_option("--max-run-seconds", sp.max_run_seconds,
                                "Skip a setting whose first step predicts more CPU seconds per simulated second")
        ->check(CLI::PositiveNumber);
    stiff_precision->add_option("--max-sweep-seconds", sp.max_sweep_seconds,
                                "Stop an integrator's sweep at one size once its runs took this long")
        ->check(CLI::PositiveNumber);
    stiff_precision->add_option("--csv", sp.csv, "Write the sweep as CSV");
    stiff_precision->add_option("--plots", sp.plot_dir, "Write stiff-precision-SIZE.png here (needs --csv; gnuplot)");
    bench::SubstepSweepOptions ss;
    CLI::App* substep_sweep = app.add_subcommand(
        "substep-sweep", "Error against substeps per 1/60 s step for every integrator (docs/ACCURACY.md)");
    substep_sweep->add_option("--T", ss.durations, "Simulated seconds per run (whole 1/60 s steps)")
        ->delimiter(',')
        ->check(CLI::PositiveNumber);
    substep_sweep->add_option("--max-substeps", ss.max_substeps, "Largest substeps per step (1, 2, 4, ... up to it)")
        ->check(CLI::Range(1, kMaxSubsteps));
    substep_sweep->add_option("--integrators", ss.integrators, "Integrators to sweep")->delimiter(',');
    substep_sweep->add_option("--csv", ss.csv, "Write the sweep as CSV");
    substep_sweep->add_option("--plots", ss.plot_dir, "Write accuracy-substeps.png here (needs --csv; gnuplot)");
    bench::StabilityOptions st;
    CLI::App* stability = app.add_subcommand(
        "stability", "Largest stable substep by bisection against the predicted one (docs/STABILITY.md)");
    stability->add_option("--T", st.duration, "Simulated seconds per trial (at least 200 substeps)")
        ->check(CLI::PositiveNumber);
    stability->add_option("--csv", st.csv, "Write the sweep as CSV");
    stability->add_option("--plot", st.plot, "Write the measured-against-predicted PNG (needs --csv; gnuplot)");
    bench::SkippingOptions sk;
    CLI::App* skipping = app.add_subcommand(
        "skipping", "What unneeded stages cost: far collider, zero stiffness, sleeping, broad phase (docs/PERFORMANCE.md)");
    skipping->add_option("--sizes", sk.sizes, "Grid sizes of the hanging cases")->delimiter(',');
    skipping->add_option("--repeats", sk.repeats, "Interleaved repetitions (medians)")->check(CLI::Range(1, 1000));
    skipping->add_option("--min-seconds", sk.min_seconds, "Minimum length of one repetition")->check(CLI::PositiveNumber);
    skipping->add_option("--csv", sk.csv, "Write the table as CSV");
    skipping->add_option("--self-threads", sk.self_threads, "solver.threads of the self-collision cases (0: the scene's)")
        ->check(CLI::Range(0, 64));
    bench::RealtimeOptions rt;
    CLI::App* realtime = app.add_subcommand(
        "realtime", "Wall seconds per simulated second of every bundled scene as the app steps it (README)");
    realtime->add_option("--T", rt.duration, "Simulated seconds per run")->check(CLI::PositiveNumber);
    realtime->add_option("--threads", rt.threads, "solver.threads of the runs")->delimiter(',');
    realtime->add_option("--repeats", rt.repeats, "Interleaved runs per case (median)")->check(CLI::Range(1, 50));
    realtime->add_option("--csv", rt.csv, "Write the table as CSV");
    realtime->add_option("--scenes", rt.scenes, "Only these bundled scenes")->delimiter(',');
    bench::ContentionOptions ct;
    CLI::App* contention = app.add_subcommand(
        "contention", "Each threaded path with 0, 1 and 2 busy processes beside it, at 1, 2 and the default threads");
    contention->add_option("--sizes", ct.sizes, "Grid sizes (particles per side)")->delimiter(',');
    contention->add_option("--loads", ct.loads, "Busy processes beside the simulation")->delimiter(',');
    contention->add_option("--paths", ct.paths, "Paths: verlet, verlet-contact, xpbd")->delimiter(',');
    contention->add_option("--rounds", ct.rounds, "Paired rounds per case (medians)")->check(CLI::Range(1, 1000));
    contention->add_option("--min-seconds", ct.min_seconds, "Length of one round at one thread's speed")
        ->check(CLI::PositiveNumber);
    contention->add_option("--csv", ct.csv, "Write the table as CSV");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    if (!kernel_name.empty() && !MassSpring::use_fast_kernel(kernel_name)) {
        std::fprintf(stderr, "clothsim-bench: --kernel %s: not a kernel this CPU runs (best here: %s)\n",
                     kernel_name.c_str(), MassSpring::fast_kernel_name());
        return 2;
    }
    if (*work_precision) return bench::run_work_precision(wp);
    if (*stiff_precision) return bench::run_stiff_precision(sp);
    if (*stability) return bench::run_stability(st);
    if (*substep_sweep) return bench::run_substep_sweep(ss);
    if (*skipping) return bench::run_skipping(sk);
    if (*realtime) return bench::run_realtime(rt);
    if (*contention) return bench::run_contention(ct);

    std::vector<Row> rows;
    try {
        for (int size : sizes) {
            double textbook = 0, aos = 0;
            {
                MassSpring sim = build_simulation(grid_scene(scene, size, SolverMethod::Textbook, 1));
                bench::TextbookAos plain(sim);
                aos = median_seconds([&] { plain.step(); }, repeats, min_seconds);
                textbook = median_seconds([&] { sim.substep(); }, repeats, min_seconds);
                require_finite(sim, scene, size);
                rows.push_back({size, sim.particle_count(), sim.spring_count(), "textbook-aos", 1, aos,
                                textbook / aos, 1.0});
                rows.push_back({size, sim.particle_count(), sim.spring_count(), "textbook", 1, textbook, 1.0,
                                aos / textbook});
            }
            for (int t : thread_counts) {
                MassSpring sim = build_simulation(grid_scene(scene, size, SolverMethod::Fast, t));
                const double fast = median_seconds([&] { sim.substep(); }, repeats, min_seconds);
                require_finite(sim, scene, size);
                rows.push_back({size, sim.particle_count(), sim.spring_count(), "fast", sim.solver_threads(), fast,
                                textbook / fast, aos / fast});
            }
        }
    } catch (const std::exception& e) {  // SceneError, or a cloth that became non-finite
        std::cerr << "clothsim-bench: error: " << e.what() << "\n";
        return 2;
    }

    // The frame budget: whole substeps of the fast solver (all threads) that fit in budget_ms beside what the
    // renderer needs from the core every frame (positions and vertex normals).
    struct Budget {
        int size;
        double substep_ms, render_prep_ms;
        long long substeps;
    };
    std::vector<Budget> budgets;
    for (int size : {128, 256}) {
        MassSpring sim = build_simulation(grid_scene(scene, size, SolverMethod::Fast, 0));
        const double substep = median_seconds([&] { sim.substep(); }, repeats, min_seconds);
        std::vector<glm::vec3> normals, positions;
        const double prep = median_seconds(
            [&] {
                sim.positions(positions);
                compute_vertex_normals(sim.topology(), sim.state().position, normals);
            },
            repeats, min_seconds);
        const double left = budget_ms * 1e-3 - prep;
        budgets.push_back({size, 1e3 * substep, 1e3 * prep, left > 0 ? static_cast<long long>(left / substep) : 0});
    }

    // The kernel's arithmetic rate against the FMA peak of the vectors it uses, per core it ran on.
    const std::string kernel = MassSpring::fast_kernel_name();
    const double peak = bench::fma_peak_gflops(kernel);
    auto gflops = [](const Row& r) { return bench::kFlopsPerSpring * r.springs / r.seconds_per_step * 1e-9; };
    std::printf("%6s %9s %9s %12s %7s %12s %12s %12s %10s %9s %9s %8s %8s\n", "size", "particles", "springs",
                "method", "threads", "ns/particle", "ns/spring", "steps/s", "B/particle", "vs soa", "vs aos",
                "GFLOP/s", "of peak");
    for (const Row& r : rows) {
        std::printf("%6d %9zu %9zu %12s %7d %12.3f %12.4f %12.0f %10.0f %9.2f %9.2f %8.1f %7.1f%%\n", r.size,
                    r.particles, r.springs, r.method.c_str(), r.threads, 1e9 * r.seconds_per_step / r.particles,
                    1e9 * r.seconds_per_step / r.springs, 1.0 / r.seconds_per_step, state_bytes_per_particle(r.method),
                    r.speedup, r.speedup_aos, gflops(r), 100.0 * gflops(r) / (peak * r.threads));
    }
    std::printf("\nfast solver kernel: %s; its FMA peak on one core, measured: %.1f GFLOP/s (%.0f flops counted "
                "per spring: bench/fma_peak.hpp)\n",
                kernel.c_str(), peak, bench::kFlopsPerSpring);
    std::printf("frame budget %.1f ms (fast solver, %d threads):\n", budget_ms,
                build_simulation(grid_scene(scene, 32, SolverMethod::Fast, 0)).solver_threads());
    for (const Budget& b : budgets) {
        std::printf("  %dx%d: substep %.4f ms, positions + normals %.4f ms -> %lld substeps per frame\n", b.size,
                    b.size, b.substep_ms, b.render_prep_ms, b.substeps);
    }
    if (!json_path.empty()) {
        nlohmann::json j;
        j["kernel"] = kernel;
        j["fma_peak_gflops_per_core"] = peak;
        j["flops_per_spring"] = bench::kFlopsPerSpring;
        for (const Row& r : rows) {
            j["rows"].push_back({{"size", r.size}, {"particles", r.particles}, {"springs", r.springs},
                                 {"method", r.method}, {"threads", r.threads},
                                 {"ns_per_particle_step", 1e9 * r.seconds_per_step / r.particles},
                                 {"ns_per_spring_step", 1e9 * r.seconds_per_step / r.springs},
                                 {"steps_per_second", 1.0 / r.seconds_per_step},
                                 {"state_bytes_per_particle", state_bytes_per_particle(r.method)},
                                 {"speedup_vs_textbook", r.speedup}, {"speedup_vs_textbook_aos", r.speedup_aos},
                                 {"gflops", gflops(r)}, {"fraction_of_fma_peak", gflops(r) / (peak * r.threads)}});
        }
        for (const Budget& b : budgets) {
            j["frame_budget"].push_back({{"size", b.size}, {"budget_ms", budget_ms}, {"substep_ms", b.substep_ms},
                                         {"render_prep_ms", b.render_prep_ms}, {"substeps", b.substeps}});
        }
        std::ofstream out(json_path);
        out << j.dump(2) << "\n";
        if (!out) {
            std::cerr << "clothsim-bench: error: cannot write " << json_path << "\n";
            return 2;
        }
    }
    if (!csv_path.empty()) {
        std::ofstream out(csv_path);
        out << "size,particles,springs,method,threads,ns_per_particle_step,ns_per_spring_step,steps_per_second,"
               "state_bytes_per_particle,speedup_vs_textbook,speedup_vs_textbook_aos\n";
        for (const Row& r : rows) {
            out << r.size << ',' << r.particles << ',' << r.springs << ',' << r.method << ',' << r.threads << ','
                << 1e9 * r.seconds_per_step / r.particles << ',' << 1e9 * r.seconds_per_step / r.springs << ','
                << 1.0 / r.seconds_per_step << ',' << state_bytes_per_particle(r.method) << ',' << r.speedup << ','
                << r.speedup_aos << '\n';
        }
        if (!out) {
            std::cerr << "clothsim-bench: error: cannot write " << csv_path << "\n";
            return 2;
        }
    }
    return 0;
}
