#include "substep_sweep.hpp"

#include "csv.hpp"
#include "plot.hpp"

#include "clothsim/reference.hpp"
#include "clothsim/scene.hpp"

#include "per_spring_scenes.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace clothsim::bench {
namespace {

using Clock = std::chrono::steady_clock;

constexpr float kStep = 1.0f / 60.0f;  // s: one step (an app frame); the sweep divides it into substeps

// The smooth scene: the bundled hanging cloth at 32 x 32 without the ground (damping 0.2 as in the file), in
// the per-spring form docs/ACCURACY.md's figures measured (tests/fixtures/per_spring_scenes.hpp).
Scene sweep_scene() {
    Scene s = per_spring_scene("hanging");
    s.cloth.rows = s.cloth.cols = 32;
    s.settings.colliders.shapes.clear();  // no ground
    s.settings.integration.dt = kStep;
    s.name = "smooth-32";
    return s;
}

struct Run {
    int substeps = 0;
    bool finite = false;
    bool stable = false;    // finite and the error below 1 (the cloth size)
    bool moved = false;     // some position changed from the start (small substeps can round every update away)
    double seconds = 0.0;   // wall time of the steps (not the build)
    ErrorNorms error;
};

Run run(const Scene& base, const std::string& integrator, int substeps, long long steps,
        const std::vector<glm::dvec3>& reference) {
    Scene s = base;
    apply_override(s, "integration.integrator=" + integrator);
    s.settings.integration.substeps = substeps;
    // Implicit Euler's CG to 1e-6 (its default 1e-5 leaves a floor above its truncation error at large counts);
    // `projective` at its defaults, which must get more accurate with more substeps on their own.
    if (integrator == "implicit-euler") s.settings.integration.tolerance = 1e-6f;
    MassSpring sim = build_simulation(s);
    Run r;
    r.substeps = substeps;
    const auto start = sim.positions();
    const auto t0 = Clock::now();
    sim.run_steps(steps);
    r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    r.moved = sim.positions() != start;
    r.finite = sim.all_finite();
    if (r.finite) r.error = relative_error(sim, reference, cloth_size(s));
    r.stable = r.finite && r.error.max < 1.0;
    return r;
}

// What the project requires of a sweep: the error falls at the integrator's order down to a floor (the smallest
// error), and no larger substep count rises above 2x that floor. Orders are taken down to the floor: between
// consecutive levels while the coarser one is above 2x the floor (within 2x it is on the floor).
struct Summary {
    bool any_stable = false;
    double floor = 0.0;
    int floor_substeps = 0;
    double worst_ratio = 0.0;    // largest error above floor_substeps / floor (infinite: unstable there)
    int worst_substeps = 0;
    std::vector<std::pair<int, double>> orders;  // (substeps, observed order from the level before)
    double seconds = 0.0;        // wall time of the whole sweep
};

Summary summarize(const std::vector<Run>& runs) {
    Summary m;
    for (const Run& r : runs) {
        m.seconds += r.seconds;
        if (r.stable && (!m.any_stable || r.error.max < m.floor)) {
            m.any_stable = true;
            m.floor = r.error.max;
            m.floor_substeps = r.substeps;
        }
    }
    if (!m.any_stable) return m;
    for (std::size_t k = 0; k < runs.size(); ++k) {
        const Run& r = runs[k];
        if (r.substeps > m.floor_substeps) {
            const double ratio = r.stable ? r.error.max / m.floor : std::numeric_limits<double>::infinity();
            if (ratio > m.worst_ratio) {
                m.worst_ratio = ratio;
                m.worst_substeps = r.substeps;
            }
        } else if (k > 0 && r.stable && runs[k - 1].stable && runs[k - 1].error.max > 2.0 * m.floor &&
                   r.error.max > 0.0) {
            const double order = std::log(runs[k - 1].error.max / r.error.max) /
                                 std::log(static_cast<double>(r.substeps) / runs[k - 1].substeps);
            m.orders.emplace_back(r.substeps, order);
        }
    }
    return m;
}

std::string format_number(const char* spec, double value) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, spec, value);
    return buffer;
}

std::string orders_text(const Summary& m) {
    std::string text;
    for (const auto& [substeps, order] : m.orders) {
        if (!text.empty()) text += ' ';
        text += format_number("%.2f", order) + "@" + std::to_string(substeps);
    }
    return text.empty() ? "-" : text;
}

std::string worst_text(const Summary& m) {
    if (m.worst_substeps == 0) return "- (floor at the largest count)";
    if (std::isinf(m.worst_ratio)) return "unstable at " + std::to_string(m.worst_substeps);
    return format_number("%.2f", m.worst_ratio) + "x at " + std::to_string(m.worst_substeps);
}

struct Sweep {
    std::string label;  // T as given, for the CSV, the tables and the plot ("0.25")
    double simulated = 0.0;
    std::vector<std::vector<Run>> runs;  // per integrator
};

void print_markdown(const Sweep& sweep, const std::vector<std::string>& integrators) {
    std::printf("\n#### T = %s s: max error / cloth size against substeps per 1/60 s step\n\n| substeps |",
                sweep.label.c_str());
    for (const std::string& name : integrators) std::printf(" %s |", name.c_str());
    std::printf("\n|---:|");
    for (std::size_t i = 0; i < integrators.size(); ++i) std::printf("---:|");
    std::printf("\n");
    for (std::size_t level = 0; level < sweep.runs.front().size(); ++level) {
        std::printf("| %d |", sweep.runs.front()[level].substeps);
        for (const std::vector<Run>& runs : sweep.runs) {
            const Run& r = runs[level];
            std::printf(" %s%s |", r.stable ? format_number("%.2e", r.error.max).c_str() : "unstable",
                        r.moved ? "" : "*");
        }
        std::printf("\n");
    }
    bool frozen = false;
    for (const std::vector<Run>& runs : sweep.runs) {
        for (const Run& r : runs) frozen = frozen || !r.moved;
    }
    if (frozen) std::printf("\n\\* the cloth did not move from its start: every position update was rounded away\n");
    std::printf("\n| integrator | floor | at substeps | worst above the floor (/ floor) | orders down to the floor "
                "(order@substeps) |\n|---|---:|---:|---|---|\n");
    for (std::size_t i = 0; i < integrators.size(); ++i) {
        const Summary m = summarize(sweep.runs[i]);
        if (!m.any_stable) {
            std::printf("| %s | unstable | - | - | - |\n", integrators[i].c_str());
            continue;
        }
        std::printf("| %s | %.2e | %d | %s | %s |\n", integrators[i].c_str(), m.floor, m.floor_substeps,
                    worst_text(m).c_str(), orders_text(m).c_str());
    }
}

}  // namespace

int run_substep_sweep(const SubstepSweepOptions& options) {
    if (!options.plot_dir.empty() && options.csv.empty()) {
        std::cerr << "clothsim-bench: error: substep-sweep --plots needs --csv\n";
        return 2;
    }
    const Scene scene = sweep_scene();
    for (const std::string& name : options.integrators) {
        try {
            Scene s = scene;
            apply_override(s, "integration.integrator=" + name);
        } catch (const SceneError& e) {
            std::cerr << "clothsim-bench: error: substep-sweep: " << e.what() << "\n";
            return 2;
        }
    }
    for (double duration : options.durations) {
        if (std::llround(duration / static_cast<double>(kStep)) < 1) {
            std::cerr << "clothsim-bench: error: substep-sweep: T = " << duration << " s is less than half a step\n";
            return 2;
        }
    }
    std::ofstream csv;
    if (!open_csv(options.csv,
                  "T,simulated_seconds,integrator,substeps,steps,substep,finite,stable,wall_seconds,error_max,"
                  "error_rms,reference_substep,reference_halving_change,moved",
                  csv)) {
        return 2;
    }
    std::printf("substep-sweep: %s, %d x %d, ground off, damping %g, step %.6g s; substeps per step 1 .. %d\n",
                scene.name.c_str(), scene.cloth.rows, scene.cloth.cols, scene.settings.springs.damping,
                static_cast<double>(kStep), options.max_substeps);
    std::vector<Sweep> sweeps;
    for (double duration : options.durations) {
        Sweep sweep;
        sweep.label = format_number("%g", duration);
        const long long steps = std::llround(duration / static_cast<double>(kStep));
        // The substep count is a power of two, so dt / substeps is exact in float and the runs end at exactly
        // steps x float(1/60) seconds: the reference is taken there.
        sweep.simulated = static_cast<double>(steps) * static_cast<double>(kStep);
        const auto t0 = Clock::now();
        const Reference ref = reference_solution(scene, sweep.simulated, 2e-4, 1e-10, 10);
        std::printf("T = %s s (%lld steps, %.9g s): reference RK4 in double at h = %.3g s after %d halvings; the last "
                    "halving changed positions by %.3g of the cloth size (%s 1e-10) [%.1f s]\n",
                    sweep.label.c_str(), steps, sweep.simulated, ref.substep, ref.halvings, ref.halving_change,
                    ref.converged ? "below" : "NOT below", std::chrono::duration<double>(Clock::now() - t0).count());
        std::fflush(stdout);
        for (const std::string& name : options.integrators) {
            std::vector<Run>& runs = sweep.runs.emplace_back();
            for (int substeps = 1; substeps <= options.max_substeps; substeps *= 2) {
                const Run r = run(scene, name, substeps, steps, ref.positions);
                runs.push_back(r);
                const double h = static_cast<double>(kStep) / substeps;
                std::printf("  %-16s substeps %5d  h = %-10.4g %-8s %9.3f s", name.c_str(), substeps, h,
                            !r.finite ? "NaN" : r.stable ? "stable" : "unstable", r.seconds);
                if (r.finite) std::printf("   error max %.3e  rms %.3e", r.error.max, r.error.rms);
                if (!r.moved) std::printf("   did not move");
                std::printf("\n");
                std::fflush(stdout);
                if (csv) {
                    csv << sweep.label << ',' << sweep.simulated << ',' << name << ',' << substeps << ',' << steps
                        << ',' << h << ',' << (r.finite ? 1 : 0) << ',' << (r.stable ? 1 : 0) << ',' << r.seconds
                        << ',';
                    if (r.finite) {
                        csv << r.error.max << ',' << r.error.rms;
                    } else {
                        csv << "nan,nan";
                    }
                    csv << ',' << ref.substep << ',' << ref.halving_change << ',' << (r.moved ? 1 : 0) << '\n';
                }
            }
            const Summary m = summarize(runs);
            if (!m.any_stable) {
                std::printf("  %-16s T = %s: no stable run [%.1f s]\n", name.c_str(), sweep.label.c_str(), m.seconds);
            } else {
                std::printf("  %-16s T = %s: floor %.3e at %d substeps; worst above it %s (%s); orders down to the "
                            "floor %s [%.1f s]\n",
                            name.c_str(), sweep.label.c_str(), m.floor, m.floor_substeps, worst_text(m).c_str(),
                            m.worst_ratio <= 2.0 ? "within 2x: holds" : "ABOVE 2x", orders_text(m).c_str(),
                            m.seconds);
            }
            std::fflush(stdout);
        }
        sweeps.push_back(std::move(sweep));
    }
    for (const Sweep& sweep : sweeps) print_markdown(sweep, options.integrators);
    if (csv) {
        csv.close();
        if (!csv) {
            std::cerr << "clothsim-bench: error: cannot write " << options.csv << "\n";
            return 2;
        }
    }
    if (!options.plot_dir.empty()) {
        std::error_code ignored;
        std::filesystem::create_directories(options.plot_dir, ignored);
        std::string durations, integrators;
        for (const Sweep& sweep : sweeps) durations += (durations.empty() ? "" : " ") + sweep.label;
        for (const std::string& name : options.integrators) integrators += (integrators.empty() ? "" : " ") + name;
        const std::string png = options.plot_dir + "/accuracy-substeps.png";
        if (!plot("plot_substep_sweep.gnuplot",
                  {{"csv", options.csv}, {"durations", durations}, {"integrators", integrators}}, png, "\n")) {
            return 2;
        }
    }
    return 0;
}

}  // namespace clothsim::bench
