// clothsim-soak: long headless runs of one scene per collider type, checked for blow-ups, energy growth,
// memory growth and a cloth that leaves the scene.
//
// Each scene (sphere: drape-sphere, cube: drape-cube, ground: falling) is built by the same builder as the
// app (build_simulation), resized to --size x --size, never allowed to sleep (solver.sleep_speed = 0, so
// every step really integrates), and stepped --steps whole steps of integration.dt. At --samples evenly
// spaced points (the first at step 0, the last at the final step) it records the step, the simulated time,
// the resident set size, the total and kinetic energy, whether every position is finite, the largest spring
// strain and the wall time, and checks:
//   - finite:  every position is finite at every sample;
//   - energy:  the total energy never exceeds E(0) + |E(0)| + 1 J (see energy_bound());
//   - memory:  the RSS grows by less than --rss-limit-kib (1 MiB) from the 2nd sample to the last;
//   - bounds:  the cloth stays in the scene (see Bounds).
// A PASS or FAIL line is printed per scene, then a summary table; the exit status is 1 when any check
// failed, 2 for a usage or scene error. scripts/soak runs the full 10^6-step soak; tests/soak the short one.
#include "csv.hpp"

#include "clothsim/collider.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include "per_spring_scenes.hpp"

#include <CLI/CLI.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

using namespace clothsim;
using Clock = std::chrono::steady_clock;

// The collider type each soak scene exercises, and the bundled scene that holds it.
struct SoakScene {
    std::string key;    // sphere, cube, ground
    std::string scene;  // bundled scene name
};
const std::vector<SoakScene> kSoakScenes = {{"sphere", "drape-sphere"}, {"cube", "drape-cube"}, {"ground", "falling"}};

// Resident set size in KiB: /proc/self/statm's second field (resident pages) x the page size; -1 when it
// cannot be read (not Linux).
long long rss_kib() {
    std::FILE* f = std::fopen("/proc/self/statm", "r");
    if (!f) return -1;
    long long size = 0, resident = -1;
    const int read = std::fscanf(f, "%lld %lld", &size, &resident);
    std::fclose(f);
    if (read != 2) return -1;
    return resident * (static_cast<long long>(sysconf(_SC_PAGESIZE)) / 1024);
}

// The stability issue's criterion (docs/STABILITY.md): "a run counts as stable when every position is finite
// and the total energy has not grown past twice its start". For E(0) > 0, twice the start is E(0) + |E(0)|.
// The energy's zero is arbitrary (gravity potential is -m g . x, zero at y = 0), so E(0) may be negative or
// near 0, where "twice" would be below the start or no room at all: |E(0)| keeps the allowed growth equal to
// the start's magnitude whatever its sign, and 1 J of slack covers a start near 0 (float round-off of the
// energy of a cloth at rest is far below 1 J; a blow-up goes orders of magnitude past it). Nothing in these
// scenes adds energy (no wind, no moving pins): damping and friction only remove it, so any growth past this
// bound is the integrator, not the physics.
double energy_bound(double e0) { return e0 + std::fabs(e0) + 1.0; }

// Where a sane cloth can be. A free cloth cannot reach farther from its start than its own diagonal plus
// what it slides; we allow the start box (and the enabled colliders) grown by twice the diagonal on every
// side. It must not fall through the ground nor sink into the sphere, the cube or the cylinder: the collision stage
// keeps every particle `thickness` (5 mm) outside each surface after every substep, so a particle more than
// kPenetration inside one has leaked through it. And no spring may be stretched past the guard's blow-up
// strain (GuardSettings::max_strain, 1000%): a cloth that far from rest has blown up even if it is finite.
constexpr float kPenetration = 0.01f;  // m
struct Bounds {
    glm::vec3 lo{0.0f}, hi{0.0f};
    double max_strain = GuardSettings{}.max_strain;
};

Bounds sane_bounds(const MassSpring& sim) {
    // The start cloth, the enabled sphere, cube and cylinder, and down to the ground: what the app frames.
    glm::vec3 lo, hi;
    scene_bounds(sim, lo, hi);
    // The cloth's diagonal: the largest distance between two particles of an unstretched cloth.
    const float diagonal = glm::length(sim.position(sim.particle_count() - 1) - sim.position(0));
    return {lo - glm::vec3(2.0f * diagonal), hi + glm::vec3(2.0f * diagonal), Bounds{}.max_strain};
}

// An empty string when the cloth is within `b`, else what is wrong (the first particle found).
std::string bounds_violation(const MassSpring& sim, const Bounds& b, double strain) {
    const ColliderSettings& c = sim.settings().colliders;
    char buf[256], where[96];
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const glm::vec3 p = sim.position(i);
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;  // the finite check's
        const char* what = nullptr;
        float depth = 0.0f;
        if (glm::any(glm::lessThan(p, b.lo)) || glm::any(glm::greaterThan(p, b.hi))) {
            what = "outside the scene box";
        } else {
            for (std::size_t k = 0; k < c.shapes.size() && !what; ++k) {
                const Collider& collider = c.shapes[k];
                if (!collider.enabled || (depth = -signed_distance(collider, p)) <= kPenetration) continue;
                std::snprintf(where, sizeof where, "inside collider %zu (%s)", k, std::string(kind_name(collider)).c_str());
                what = where;
            }
        }
        if (what) {
            std::snprintf(buf, sizeof buf, "particle %zu at (%.4g, %.4g, %.4g) %s", i, p.x, p.y, p.z, what);
            if (depth > 0.0f) std::snprintf(buf + std::strlen(buf), sizeof buf - std::strlen(buf), " by %.4g m", depth);
            return buf;
        }
    }
    if (strain > b.max_strain) {
        std::snprintf(buf, sizeof buf, "max strain %.4g above the guard's blow-up strain %.4g", strain, b.max_strain);
        return buf;
    }
    return {};
}

struct Sample {
    long long step = 0;
    double time = 0, wall = 0;
    long long rss = 0;  // KiB
    double energy = 0, kinetic = 0, strain = 0;
    bool finite = true;
    std::string bounds;  // empty: within the sane bounds
};

struct Result {
    std::string key, scene, colliders;
    int size = 0, substeps = 0, scene_substeps = 0, threads = 1;
    long long steps = 0;
    std::vector<Sample> samples;
    std::vector<std::string> failures;
};

std::string enabled_colliders(const ColliderSettings& c) {
    std::string s;
    for (const Collider& collider : c.shapes) {
        if (collider.enabled) s += std::string(kind_name(collider)) + " ";
    }
    if (s.empty()) return "none";
    s.pop_back();
    return s;
}

struct Options {
    long long steps = 1'000'000;
    int size = 16;
    int samples = 100;
    int threads = 1;
    long long rss_limit_kib = 1024;
    std::vector<std::string> scenes{"sphere", "cube", "ground"};
    std::vector<std::string> overrides;  // --set key=value, applied to every scene after the resize
    bool keep_substeps = false;          // no auto substeps: step exactly the scene's (or --set's) substeps
    std::string csv;
    bool progress = false;
};

Result soak(const SoakScene& which, const Options& opt, std::ofstream& csv) {
    // A bundled scene in its per-spring form (tests/fixtures/per_spring_scenes.hpp): the recorded soaks' workload.
    Scene scene = load_per_spring(which.scene);
    const ColliderSettings& bundled = scene.settings.colliders;
    // The key names a first-form section (sphere, cube, ground): its kind must be enabled in the scene.
    const int kind = find_collider_kind(which.key);
    const bool has_collider = which.key == which.scene ||
                              std::any_of(bundled.shapes.begin(), bundled.shapes.end(), [&](const Collider& c) {
                                  return c.enabled && static_cast<int>(c.kind()) == kind;
                              });
    if (!has_collider) {
        throw SceneError("scene '" + which.scene + "' is meant to soak the " + which.key +
                         " collider but does not enable it (colliders: " + enabled_colliders(bundled) + ")");
    }
    scene.cloth.rows = scene.cloth.cols = opt.size;
    scene.settings.solver.sleep_speed = 0.0f;  // never sleep: every one of the steps integrates
    scene.settings.solver.threads = opt.threads;
    for (const std::string& assignment : opt.overrides) apply_override(scene, assignment);
    validate(scene);

    Result r;
    r.key = which.key;
    r.scene = which.scene;
    r.colliders = enabled_colliders(scene.settings.colliders);
    r.size = opt.size;
    r.steps = opt.steps;
    r.scene_substeps = scene.settings.integration.substeps;
    if (!opt.keep_substeps) {
        // Keep the substeps the scene holds, unless the resized cloth needs more (safety 0.67 of the
        // predicted critical substep, as docs/STABILITY.md's auto substeps).
        const MassSpring probe = build_simulation(scene);
        scene.settings.integration.substeps =
            auto_substeps(stability_limit(probe), scene.settings.integration.dt, 0.67f, r.scene_substeps);
    }
    r.substeps = scene.settings.integration.substeps;
    MassSpring sim = build_simulation(scene);
    r.threads = sim.solver_threads();
    const Bounds bounds = sane_bounds(sim);

    const int k = std::max(opt.samples, 2);
    const auto t0 = Clock::now();
    long long done = 0;
    for (int i = 0; i < k; ++i) {
        const long long target = static_cast<long long>((static_cast<long double>(opt.steps) * i) / (k - 1));
        sim.run_steps(target - done);
        done = target;
        Sample s;
        s.wall = std::chrono::duration<double>(Clock::now() - t0).count();
        s.step = done;
        s.time = sim.time();
        s.rss = rss_kib();
        const Energy e = sim.energy();
        s.energy = e.total();
        s.kinetic = e.kinetic;
        s.finite = sim.all_finite();
        s.strain = max_strain(sim);
        s.bounds = bounds_violation(sim, bounds, s.strain);
        r.samples.push_back(s);
        if (csv.is_open()) {
            csv << r.key << ',' << r.scene << ',' << opt.size << ',' << r.substeps << ',' << i << ',' << s.step << ','
                << s.time << ',' << s.rss << ',' << s.energy << ',' << s.kinetic << ',' << (s.finite ? 1 : 0) << ','
                << s.strain << ',' << (s.bounds.empty() ? 1 : 0) << ',' << s.wall << '\n';
            csv.flush();
        }
        if (opt.progress) {
            std::fprintf(stderr, "  %s %3d/%d step %lld t=%.1f s rss=%lld KiB E=%.6g J K=%.3g J strain=%.4g wall=%.1f s\n",
                         r.key.c_str(), i + 1, k, s.step, s.time, s.rss, s.energy, s.kinetic, s.strain, s.wall);
        }
    }

    // The checks, over all samples.
    char buf[320];
    const double e0 = r.samples.front().energy;
    for (const Sample& s : r.samples) {
        if (!s.finite) {
            std::snprintf(buf, sizeof buf, "non-finite position at step %lld", s.step);
            r.failures.push_back(buf);
            break;
        }
    }
    for (const Sample& s : r.samples) {
        if (!(s.energy <= energy_bound(e0))) {  // NaN fails too
            std::snprintf(buf, sizeof buf, "energy %.6g J at step %lld exceeds E(0) + |E(0)| + 1 J = %.6g J", s.energy,
                          s.step, energy_bound(e0));
            r.failures.push_back(buf);
            break;
        }
    }
    const Sample& base = r.samples[1];  // the first sample after warm-up
    const Sample& last = r.samples.back();
    if (base.rss < 0 || last.rss < 0) {
        r.failures.push_back("cannot read the RSS from /proc/self/statm");
    } else if (last.rss - base.rss >= opt.rss_limit_kib) {
        std::snprintf(buf, sizeof buf, "RSS grew by %lld KiB from step %lld to step %lld (limit %lld KiB)",
                      last.rss - base.rss, base.step, last.step, opt.rss_limit_kib);
        r.failures.push_back(buf);
    }
    for (const Sample& s : r.samples) {
        if (!s.bounds.empty()) {
            std::snprintf(buf, sizeof buf, "out of bounds at step %lld: %s", s.step, s.bounds.c_str());
            r.failures.push_back(buf);
            break;
        }
    }
    return r;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"clothsim-soak: long runs of the sphere, cube and ground scenes, checked for blow-ups, energy "
                 "growth, memory growth and a cloth leaving the scene"};
    Options opt;
    app.add_option("--steps", opt.steps, "Steps of integration.dt per scene")->capture_default_str()->check(
        CLI::Range(1LL, 1'000'000'000'000LL));
    app.add_option("--size", opt.size, "Cloth particles per side (the scene's cloth is resized)")
        ->capture_default_str()
        ->check(CLI::Range(2, 1024));
    app.add_option("--scenes", opt.scenes,
                   "Scenes: sphere (drape-sphere), cube (drape-cube), ground (falling), or a bundled scene name")
        ->delimiter(',')
        ->capture_default_str();
    app.add_option("--samples", opt.samples, "Evenly spaced sample points, the first at step 0 and the last at the end")
        ->capture_default_str()
        ->check(CLI::Range(3, 1'000'000));
    app.add_option("--threads", opt.threads, "Fast-solver threads (0: one per core)")->capture_default_str()->check(
        CLI::Range(0, 1024));
    app.add_option("--rss-limit-kib", opt.rss_limit_kib, "Allowed RSS growth from the 2nd sample to the last")
        ->capture_default_str();
    app.add_option("--set", opt.overrides, "Override a scene field in every scene (key=value, as clothsim --set)");
    app.add_flag("--keep-substeps", opt.keep_substeps,
                 "Step the scene's substeps even when the resized cloth needs more (to see the checks fail)");
    app.add_option("--csv", opt.csv, "Write every sample as CSV");
    app.add_flag("--progress", opt.progress, "Print every sample on stderr");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }

    std::vector<SoakScene> chosen;
    for (const std::string& name : opt.scenes) {
        const auto it = std::find_if(kSoakScenes.begin(), kSoakScenes.end(),
                                     [&](const SoakScene& s) { return s.key == name || s.scene == name; });
        chosen.push_back(it != kSoakScenes.end() ? *it : SoakScene{name, name});
    }
    std::ofstream csv;
    if (!clothsim::bench::open_csv(opt.csv,
                                   "collider,scene,size,substeps,sample,step,time_s,rss_kib,energy_total_j,"
                                   "energy_kinetic_j,all_finite,max_strain,in_bounds,wall_s",
                                   csv)) {
        return 2;
    }
    csv.precision(10);

    std::printf("clothsim-soak: %lld steps per scene, %d x %d cloth, %d samples, sleep off, fast-solver kernel %s\n",
                opt.steps, opt.size, opt.size, std::max(opt.samples, 2), MassSpring::fast_kernel_name());
    std::fflush(stdout);
    std::vector<Result> results;
    bool all_pass = true;
    for (const SoakScene& which : chosen) {
        try {
            results.push_back(soak(which, opt, csv));
        } catch (const SceneError& e) {
            std::cerr << "clothsim-soak: error: " << e.what() << "\n";
            return 2;
        }
        const Result& r = results.back();
        const Sample& last = r.samples.back();
        const bool pass = r.failures.empty();
        all_pass = all_pass && pass;
        std::printf("%s %s (%s, colliders: %s, %d x %d, %d substeps%s, %d thread%s): %lld steps in %.1f s\n",
                    pass ? "PASS" : "FAIL", r.key.c_str(), r.scene.c_str(), r.colliders.c_str(), r.size, r.size,
                    r.substeps, r.substeps == r.scene_substeps ? " as the scene" : " (auto, more than the scene)",
                    r.threads, r.threads == 1 ? "" : "s", r.steps, last.wall);
        for (const std::string& f : r.failures) std::printf("  FAIL: %s\n", f.c_str());
        std::fflush(stdout);
    }

    std::printf("\n%-7s %9s %8s %9s %9s %9s %9s %9s %12s %12s %12s %12s %10s %s\n", "scene", "steps", "wall s",
                "steps/s", "RSS0 KiB", "RSS1 KiB", "last KiB", "max KiB", "E start J", "E min J", "E max J",
                "E end J", "max strain", "result");
    for (const Result& r : results) {
        double emin = r.samples.front().energy, emax = emin, strain = 0.0;
        long long rss_max = 0;
        for (const Sample& s : r.samples) {
            emin = std::min(emin, s.energy);
            emax = std::max(emax, s.energy);
            strain = std::max(strain, s.strain);
            rss_max = std::max(rss_max, s.rss);
        }
        const Sample& last = r.samples.back();
        std::printf("%-7s %9lld %8.1f %9.0f %9lld %9lld %9lld %9lld %12.6g %12.6g %12.6g %12.6g %10.4g %s\n",
                    r.key.c_str(), r.steps, last.wall, static_cast<double>(r.steps) / last.wall,
                    r.samples.front().rss, r.samples[1].rss, last.rss, rss_max, r.samples.front().energy, emin, emax,
                    last.energy, strain, r.failures.empty() ? "PASS" : "FAIL");
    }
    std::printf("RSS0: at step 0; RSS1: the 2nd sample, the baseline of the memory check (growth to the last sample "
                "under %lld KiB)\n",
                opt.rss_limit_kib);
    std::printf("%s\n", all_pass ? "clothsim-soak: all scenes PASS" : "clothsim-soak: FAIL");
    return all_pass ? 0 : 1;
}
