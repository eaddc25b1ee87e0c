// clothsim-bench work-precision: run time against error for every integrator (docs/ACCURACY.md).
#pragma once

#include <string>
#include <vector>

namespace clothsim::bench {

struct WorkPrecisionOptions {
    std::vector<std::string> scenes{"smooth", "drape", "flag"};
    std::vector<std::string> integrators{"verlet", "symplectic-euler", "rk4", "implicit-euler", "xpbd"};
    double duration = 0.5;      // s of simulated time
    int levels = 7;             // step sizes per integrator, halving from the largest stable one
    int repeats = 3;            // timed repetitions (median)
    std::string csv;            // output CSV
    std::string plot_dir;       // where to write one PNG per scene (gnuplot); empty for none
};

int run_work_precision(const WorkPrecisionOptions& options);

}  // namespace clothsim::bench
