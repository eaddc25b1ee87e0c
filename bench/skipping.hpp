// clothsim-bench skipping: what the stages a scene does not need cost (docs/PERFORMANCE.md, "Skipping").
#pragma once

#include <string>
#include <vector>

namespace clothsim::bench {

struct SkippingOptions {
    std::vector<int> sizes{32, 128};  // grid sizes (particles per side) of the hanging cases
    int repeats = 21;                 // interleaved timed repetitions per pair (medians reported)
    double min_seconds = 0.05;        // minimum length of one repetition
    std::string csv;                  // output CSV
    int self_threads = 0;             // solver.threads of the self-collision cases (0: the scene's)
};

int run_skipping(const SkippingOptions& options);

}  // namespace clothsim::bench
