// clothsim-bench stiff-precision (issue 15): work against error on stiff cloth for every integrator.
//
// The bundled `stiff-hanging` scene (cotton at its measured stretch, no ground) at several grid sizes, each
// integrator at a range of substeps per 1/60 s step, on one thread (solver.threads = 1). The error is the
// largest particle distance from a reference at T = 0.25 s, 0.5 s and 1 s, over the cloth size. The reference
// is the fast solver's Verlet at `reference_factor` times the stable substep count (the Gershgorin bound); its
// convergence is shown by Verlet at 2x and 4x against it, and the round-off floor by Verlet at 2x with gravity
// one float ulp smaller (the swinging cloth amplifies a change of 6e-8 to percents of its size by 1 s).
// Results in docs/ACCURACY.md, "Stiff cloth: work-precision".
#pragma once

#include <string>
#include <vector>

namespace clothsim::bench {

struct StiffPrecisionOptions {
    std::vector<int> sizes{32, 64, 128};  // particles per side
    std::vector<std::string> integrators{"verlet", "symplectic-euler", "rk4", "implicit-euler", "xpbd", "projective"};
    int repeats = 3;                  // timed repetitions of each setting (median)
    int reference_factor = 8;         // the reference's substeps: this times the stable count
    int min_substeps = 1;             // integrators that are not explicit run min, 2 min, 4 min, ...
    int max_substeps = 4096;          // ... up to this
    double max_run_seconds = 45.0;    // skip a setting whose first step predicts more CPU s per simulated second
    double max_sweep_seconds = 120.0; // stop an integrator's sweep at one size once its runs took this long
    std::vector<std::string> overrides; // --set KEY=VALUE for every integrator but Verlet (its reference)
    std::string csv;                  // output CSV
    std::string plot_dir;             // where to write stiff-precision-SIZE.png (gnuplot); empty for none
};

int run_stiff_precision(const StiffPrecisionOptions& options);

}  // namespace clothsim::bench
