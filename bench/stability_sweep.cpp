#include "stability_sweep.hpp"

#include "csv.hpp"
#include "plot.hpp"

#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include "per_spring_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <vector>

namespace clothsim::bench {
namespace {

struct Case {
    std::string sweep;
    Integrator integrator;
    float stiffness;  // structural; shear and bending are 10% and 2.5% of it
    float mass;       // kg, whole cloth
    float damping;    // 1/s
    int grid;         // particles per side
};

Scene scene_for(const Case& c, double h) {
    // Released flat, held by two corners: it moves from the first step. Per spring: the mass and springs below.
    Scene s = per_spring_scene("hanging");
    s.cloth.rows = s.cloth.cols = c.grid;
    s.cloth.mass = c.mass;
    s.settings.springs.structural = glm::vec2(c.stiffness);
    s.settings.springs.shear = 0.1f * c.stiffness;
    s.settings.springs.bending = glm::vec2(0.025f * c.stiffness);
    s.settings.springs.damping = c.damping;
    s.settings.colliders.shapes.clear();  // no ground
    s.settings.integration.integrator = c.integrator;
    s.settings.integration.dt = static_cast<float>(h);
    s.settings.integration.substeps = 1;
    return s;
}

// Stable: after the trial every position is finite and the total energy has not grown past twice its
// start (plus a little, for a cloth starting near zero energy). Energy, not strain: a soft cloth may
// stretch a lot under gravity and still be stable; an unstable mode grows without bound within the
// 200 or more substeps of a trial.
bool stable(const Case& c, double h, double duration) {
    MassSpring sim = build_simulation(scene_for(c, h));
    const double e0 = sim.energy().total();
    const long long steps = std::max(200LL, std::llround(duration / h));
    for (long long i = 0; i < steps; ++i) {
        sim.substep();
        if ((i & 63) == 63 && !sim.all_finite()) return false;
    }
    if (!sim.all_finite()) return false;
    const double e = sim.energy().total();
    return std::isfinite(e) && e <= e0 + std::fabs(e0) + 1e-3;
}

// The largest stable h: bracket around the prediction by doubling and halving, then bisect in log space.
double measured_limit(const Case& c, double predicted, double duration) {
    double lo = 0.5 * predicted, hi = 0.0;
    for (int i = 0; i < 30 && !stable(c, lo, duration); ++i) lo *= 0.5;
    hi = 2.0 * lo;
    for (int i = 0; i < 30 && stable(c, hi, duration); ++i) {
        lo = hi;
        hi *= 2.0;
    }
    for (int i = 0; i < 12; ++i) {
        const double mid = std::sqrt(lo * hi);
        (stable(c, mid, duration) ? lo : hi) = mid;
    }
    return lo;
}

}  // namespace

int run_stability(const StabilityOptions& options) {
    std::vector<Case> cases;
    const Integrator integrators[] = {Integrator::Verlet, Integrator::SymplecticEuler, Integrator::Rk4};
    for (Integrator integrator : integrators) {
        for (float k : {1e1f, 1e2f, 1e3f, 1e4f, 1e5f, 1e6f, 1e7f}) cases.push_back({"stiffness", integrator, k, 0.5f, 0.2f, 16});
        for (float m : {0.05f, 5.0f}) cases.push_back({"mass", integrator, 1e3f, m, 0.2f, 16});
        for (float c : {0.0f, 20.0f, 200.0f}) cases.push_back({"damping", integrator, 1e3f, 0.5f, c, 16});
        for (int n : {4, 8, 32}) cases.push_back({"grid", integrator, 1e3f, 0.5f, 0.2f, n});
    }
    std::ofstream csv;
    if (!open_csv(options.csv,
                  "sweep,integrator,stiffness,mass,damping,grid,predicted_gershgorin,predicted_plane_wave,measured,"
                  "measured_over_predicted,safe",
                  csv)) {
        return 2;
    }
    std::printf("%-9s %-17s %9s %6s %7s %4s %12s %12s %12s %8s %5s\n", "sweep", "integrator", "k (N/m)", "mass",
                "damping", "grid", "predicted", "plane wave", "measured", "ratio", "safe");
    int unsafe = 0, beyond_two = 0, verlet_cases = 0;
    for (const Case& c : cases) {
        const MassSpring sim = build_simulation(scene_for(c, 1e-3));
        const StabilityLimit limit = stability_limit(sim);
        const double measured = measured_limit(c, limit.critical_substep, options.duration);
        const double ratio = measured / limit.critical_substep;
        const bool safe = ratio >= 1.0;
        if (c.integrator == Integrator::Verlet) {
            ++verlet_cases;
            unsafe += !safe;
            beyond_two += ratio > 2.0;
        }
        const std::string name(integrator_names()[static_cast<int>(c.integrator)]);
        std::printf("%-9s %-17s %9.3g %6.3g %7.3g %4d %12.4g %12.4g %12.4g %8.3f %5s\n", c.sweep.c_str(), name.c_str(),
                    c.stiffness, c.mass, c.damping, c.grid, limit.critical_substep, limit.plane_wave_substep, measured,
                    ratio, safe ? "yes" : "NO");
        if (csv) {
            csv << c.sweep << ',' << name << ',' << c.stiffness << ',' << c.mass << ',' << c.damping << ',' << c.grid
                << ',' << limit.critical_substep << ',' << limit.plane_wave_substep << ',' << measured << ',' << ratio
                << ',' << (safe ? 1 : 0) << '\n';
        }
    }
    std::printf("\nposition Verlet: predicted limit safe in %d of %d cases; measured within 2x of it in %d of %d\n",
                verlet_cases - unsafe, verlet_cases, verlet_cases - beyond_two, verlet_cases);
    if (csv) csv.close();
    if (!options.plot.empty() && !options.csv.empty()) {
        if (!plot("plot_stability.gnuplot", {{"csv", options.csv}}, options.plot)) return 2;
    }
    return 0;
}

}  // namespace clothsim::bench
