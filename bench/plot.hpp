// Runs one of bench/'s gnuplot scripts, the one place the benchmarks turn their CSV into a PNG.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

namespace clothsim::bench {

// gnuplot -e "name='value'; ...; png='PNG'" CLOTHSIM_BENCH_DIR/script. Prints "wrote PNG" (after `lead`), or
// the error; returns false when gnuplot fails.
inline bool plot(const std::string& script, const std::vector<std::pair<std::string, std::string>>& variables,
                 const std::string& png, const char* lead = "") {
    std::string assignments;
    for (const auto& [name, value] : variables) assignments += name + "='" + value + "'; ";
    const std::string command =
        "gnuplot -e \"" + assignments + "png='" + png + "'\" " + CLOTHSIM_BENCH_DIR "/" + script;
    if (std::system(command.c_str()) != 0) {
        std::cerr << "clothsim-bench: error: gnuplot failed for " << png << "\n";
        return false;
    }
    std::printf("%swrote %s\n", lead, png.c_str());
    return true;
}

}  // namespace clothsim::bench
