// clothsim-bench substep-sweep: final-position error against substeps per 1/60 s step, for every integrator
// (docs/ACCURACY.md): each integrator's error should fall at its order until it reaches a floor and then never
// rise above 2x that floor.
#pragma once

#include <string>
#include <vector>

namespace clothsim::bench {

struct SubstepSweepOptions {
    std::vector<double> durations{0.25, 0.5};  // s of simulated time (whole 1/60 s steps)
    std::vector<std::string> integrators{"verlet", "symplectic-euler", "rk4", "implicit-euler", "xpbd", "projective"};
    int max_substeps = 4096;                    // substeps per step: 1, 2, 4, ... up to this
    std::string csv;                            // output CSV
    std::string plot_dir;                       // where to write accuracy-substeps.png (gnuplot); empty for none
};

int run_substep_sweep(const SubstepSweepOptions& options);

}  // namespace clothsim::bench
