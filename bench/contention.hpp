// clothsim-bench contention: each threaded path's time per substep with other programs busy on the cores
// (docs/PERFORMANCE.md, "Threads under load").
#pragma once

#include <string>
#include <vector>

namespace clothsim::bench {

struct ContentionOptions {
    std::vector<int> sizes{64, 128, 256};  // particles per side
    std::vector<int> loads{0, 1, 2};       // busy processes started beside the simulation
    std::vector<std::string> paths{"verlet", "verlet-contact", "xpbd"};
    int rounds = 7;             // paired rounds per case (medians reported)
    double min_seconds = 0.1;   // the length of one round of one thread setting, at one thread's speed
    std::string csv;            // output CSV
};

int run_contention(const ContentionOptions& options);

}  // namespace clothsim::bench
