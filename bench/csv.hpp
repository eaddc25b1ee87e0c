// Opening a benchmark's CSV output: the header line written, or a message naming the file.
#pragma once

#include <fstream>
#include <iostream>
#include <string>

namespace clothsim::bench {

// Opens `path` (when not empty) and writes `header`; false (with a message) when it cannot be written.
inline bool open_csv(const std::string& path, const char* header, std::ofstream& out) {
    if (path.empty()) return true;
    out.open(path);
    if (!out) {
        std::cerr << "clothsim-bench: error: cannot write " << path << "\n";
        return false;
    }
    out << header << '\n';
    return true;
}

}  // namespace clothsim::bench
