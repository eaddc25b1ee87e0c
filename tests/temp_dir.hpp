// A fresh directory under the system's temporary directory (mkdtemp), removed with everything in it when the
// test leaves its scope. Shared by the tests that write files (atomic saves, mesh files).
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <string>
#include <string_view>

namespace clothsim::test {

struct TempDir {
    std::filesystem::path path;
    // `prefix` names it: /tmp/clothsim-<prefix>-XXXXXX.
    explicit TempDir(std::string_view prefix) {
        std::string name = (std::filesystem::temp_directory_path() / ("clothsim-" + std::string(prefix) + "-XXXXXX")).string();
        path = ::mkdtemp(name.data());
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
};

}  // namespace clothsim::test
