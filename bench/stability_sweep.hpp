// clothsim-bench stability: the largest stable substep found by bisection against the predicted one.
#pragma once

#include <string>

namespace clothsim::bench {

struct StabilityOptions {
    double duration = 0.05;  // s of simulated time per trial (at least 200 substeps)
    std::string csv;         // output CSV
    std::string plot;        // PNG of measured against predicted (gnuplot); empty for none
};

int run_stability(const StabilityOptions& options);

}  // namespace clothsim::bench
