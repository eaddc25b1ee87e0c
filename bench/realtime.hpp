// clothsim-bench realtime: wall seconds per simulated second of every bundled scene, stepped as the app steps
// it (auto substeps at the app's safety, the guard on), with one and with two solver threads.
#pragma once

#include <string>
#include <vector>

namespace clothsim::bench {

struct RealtimeOptions {
    double duration = 2.0;             // simulated seconds per run
    std::vector<int> threads{1, 2};    // solver.threads of the runs
    int repeats = 3;                   // runs per case, interleaved (the median is reported)
    std::string csv;                   // output CSV
    std::vector<std::string> scenes;   // only these bundled scenes (empty: all)
};

int run_realtime(const RealtimeOptions& options);

}  // namespace clothsim::bench
