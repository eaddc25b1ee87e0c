// Running the clothsim executable from tests: exit code, stdout and stderr kept apart, and temporary
// directories that clean up after themselves. Shared by the CLI and the render tests.
#pragma once

#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

// A failed check shows what the program said.
#define CAPTURE_RUN(r) INFO("exit code " << (r).code << "\nstdout:\n" << (r).out << "\nstderr:\n" << (r).err)

namespace clothsim::test {

namespace fs = std::filesystem;

struct RunResult {
    int code = -1;
    std::string out;  // stdout
    std::string err;  // stderr
};

// One argument for /bin/sh, single-quoted.
inline std::string quote(const std::string& arg) {
    std::string q = "'";
    for (char c : arg) {
        if (c == '\'') q += "'\\''";
        else q += c;
    }
    return q + "'";
}

inline std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A fresh directory for one test's files, removed when the test ends.
class TempDir {
public:
    explicit TempDir(const std::string& name)
        : path_(fs::temp_directory_path() / ("clothsim_test_" + std::to_string(::getpid()) + "_" + name)) {
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const fs::path& path() const { return path_; }
    fs::path operator/(const std::string& name) const { return path_ / name; }

private:
    fs::path path_;
};

// Runs `exe args...`; stdout through the pipe, stderr through a temporary file. `prefix` goes before the
// command, e.g. "env -u DISPLAY" or "env NAME=value".
inline RunResult run_process(const std::string& exe, const std::vector<std::string>& args,
                             const std::string& prefix = "") {
    static int counter = 0;
    const fs::path err_file =
        fs::temp_directory_path() /
        ("clothsim_test_" + std::to_string(::getpid()) + "_stderr_" + std::to_string(counter++) + ".txt");
    std::string command = prefix;
    command.append(prefix.empty() ? "" : " ").append(quote(exe));
    // Appends, not "literal" + string: GCC 12 warns falsely on that (-Wrestrict, GCC bug 105329).
    for (const std::string& a : args) command.append(" ").append(quote(a));
    command.append(" 2>").append(quote(err_file.string()));

    RunResult result;
    FILE* pipe = ::popen(command.c_str(), "r");
    REQUIRE(pipe != nullptr);
    char buffer[4096];
    std::size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.out.append(buffer, n);
    const int status = ::pclose(pipe);
    REQUIRE(WIFEXITED(status));
    result.code = WEXITSTATUS(status);
    result.err = read_file(err_file);
    std::error_code ec;
    fs::remove(err_file, ec);
    return result;
}

}  // namespace clothsim::test
