#include "work_precision.hpp"

#include "csv.hpp"
#include "plot.hpp"

#include "clothsim/reference.hpp"
#include "clothsim/scene.hpp"

#include "per_spring_scenes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>

namespace clothsim::bench {
namespace {

using Clock = std::chrono::steady_clock;

// The study's scenes: small versions of bundled ones, so the double-precision reference is affordable, in the
// per-spring form docs/ACCURACY.md's figures measured (tests/fixtures/per_spring_scenes.hpp).
//  smooth: hanging, 16 x 16, no ground, no damping (smooth and conservative: energy error is meaningful)
//  drape:  drape-sphere, 16 x 16, damped, with sphere and ground contact, penalty model (smooth; see below)
//  flag:   flag, 12 x 18, wind with gusts
Scene study_scene(const std::string& name) {
    if (name == "smooth") {
        Scene s = per_spring_scene("hanging");
        s.cloth.rows = s.cloth.cols = 16;
        s.settings.colliders.shapes.clear();  // no ground
        s.settings.springs.damping = 0.0f;
        s.name = "smooth";
        return s;
    }
    if (name == "drape") {
        Scene s = per_spring_scene("drape-sphere");
        s.cloth.rows = s.cloth.cols = 16;
        // Penalty contact, so the error has a limit to converge to (projection contact's reference does not
        // converge: docs/ACCURACY.md, "Contact in the accuracy study"). k_c = 1e4 N/m: a particle of this cloth
        // (2.3 g) rests 0.39 mm (0.08 of the 5 mm thickness) deep under its own weight, and the deepest any
        // goes in the study's 0.5 s (the impact, then the hanging cloth's pull over the sphere) is 2.4 mm
        // (0.48 t): none reaches the surface. The stability bound (3 k_c per collider, stability.cpp) puts
        // Verlet's critical substep at 0.38 ms, against 1.6 ms with projection: 4x the substeps, where 1e3 N/m
        // would let the impact push particles past the surface (1.02 t) and 3e3 N/m to 0.90 t.
        s.settings.colliders.contact = ContactModel::Penalty;
        s.settings.colliders.contact_stiffness = 1e4f;
        s.name = "drape";
        return s;
    }
    if (name == "flag") {
        Scene s = per_spring_scene("flag");
        s.cloth.rows = 12;
        s.cloth.cols = 18;
        s.name = "flag";
        return s;
    }
    throw SceneError("work-precision: unknown scene '" + name + "'; allowed: smooth, drape, flag");
}

Integrator integrator_named(const std::string& name) {
    const auto names = integrator_names();
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (names[i] == name) return static_cast<Integrator>(i);
    }
    throw SceneError("work-precision: unknown integrator '" + name + "'");
}

struct Run {
    bool finite = false;
    double seconds = 0.0;  // median wall time of the whole run
    ErrorNorms error;
    double energy_error = 0.0;  // |E(T) - E(0)| / |E(0)|
};

Run run(const Scene& base, Integrator integrator, double h, double duration, int repeats,
        const std::vector<glm::dvec3>& reference) {
    // Whole substeps that end exactly at `duration`, so every run is compared at the reference's time.
    const long long steps = std::max(1LL, std::llround(duration / h));
    h = duration / static_cast<double>(steps);
    Scene s = base;
    s.settings.integration.integrator = integrator;
    s.settings.integration.dt = static_cast<float>(h);
    s.settings.integration.substeps = 1;
    s.settings.integration.tolerance = 1e-6f;
    Run r;
    std::vector<double> times;
    for (int k = 0; k < repeats; ++k) {
        MassSpring sim = build_simulation(s);
        const double e0 = sim.energy().total();
        const auto t0 = Clock::now();
        for (long long i = 0; i < steps; ++i) sim.substep();
        times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
        r.finite = sim.all_finite();
        if (!r.finite) return r;
        r.error = relative_error(sim, reference, cloth_size(s));
        r.energy_error = std::fabs(sim.energy().total() - e0) / std::max(std::fabs(e0), 1e-30);
    }
    std::sort(times.begin(), times.end());
    r.seconds = times[times.size() / 2];
    return r;
}

}  // namespace

int run_work_precision(const WorkPrecisionOptions& options) {
    std::ofstream csv;
    if (!open_csv(options.csv,
                  "scene,integrator,substep,steps,finite,wall_seconds,seconds_per_simulated_second,error_max,"
                  "error_rms,energy_error,reference_substep,reference_halving_change",
                  csv)) {
        return 2;
    }
    for (const std::string& scene_name : options.scenes) {
        Scene scene;
        std::vector<Integrator> integrators;
        try {
            scene = study_scene(scene_name);
            for (const std::string& n : options.integrators) integrators.push_back(integrator_named(n));
        } catch (const SceneError& e) {
            std::cerr << "clothsim-bench: error: " << e.what() << "\n";
            return 2;
        }
        // The reference: double-precision RK4, halving from 0.5 ms until halving changes < 1e-9 of the size.
        const auto t0 = Clock::now();
        const Reference ref = reference_solution(scene, options.duration, 5e-4, 1e-9, 9);
        std::printf("scene %s (T = %.3g s): reference RK4 in double at h = %.3g s after %d halvings; the last "
                    "halving changed positions by %.3g of the cloth size (%s 1e-9) [%.1f s]\n",
                    scene_name.c_str(), options.duration, ref.substep, ref.halvings, ref.halving_change,
                    ref.converged ? "below" : "NOT below", std::chrono::duration<double>(Clock::now() - t0).count());
        for (Integrator integrator : integrators) {
            const std::string name(integrator_names()[static_cast<int>(integrator)]);
            // Start at the largest stable step of the form 16 ms / 2^j (stable: finite and the error < 1).
            double h = 1.0 / 64.0;
            for (int j = 0; j < 12; ++j, h *= 0.5) {
                const Run probe = run(scene, integrator, h, options.duration, 1, ref.positions);
                if (probe.finite && probe.error.max < 1.0) break;
            }
            for (int level = 0; level < options.levels; ++level, h *= 0.5) {
                const Run r = run(scene, integrator, h, options.duration, options.repeats, ref.positions);
                const long long steps = std::llround(options.duration / h);
                std::printf("  %-16s h = %-10.4g %s  %8.4f s per simulated s   error max %.3e  rms %.3e  energy %.3e\n",
                            name.c_str(), h, r.finite ? "finite" : "NaN   ", r.seconds / options.duration,
                            r.error.max, r.error.rms, r.energy_error);
                if (csv) {
                    csv << scene_name << ',' << name << ',' << h << ',' << steps << ',' << (r.finite ? 1 : 0) << ','
                        << r.seconds << ',' << r.seconds / options.duration << ',' << r.error.max << ','
                        << r.error.rms << ',' << r.energy_error << ',' << ref.substep << ',' << ref.halving_change
                        << '\n';
                }
                if (!r.finite) break;
            }
        }
    }
    if (csv) csv.close();
    if (!options.plot_dir.empty() && !options.csv.empty()) {
        for (const std::string& scene_name : options.scenes) {
            const std::string png = options.plot_dir + "/accuracy-" + scene_name + ".png";
            if (!plot("plot_work_precision.gnuplot", {{"csv", options.csv}, {"scene", scene_name}}, png)) return 2;
        }
    }
    return 0;
}

}  // namespace clothsim::bench
