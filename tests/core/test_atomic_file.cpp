// write_file_atomically: the target is the old file or the whole new one, whatever goes wrong.
#include "clothsim/atomic_file.hpp"
#include "temp_dir.hpp"

#include <catch2/catch.hpp>

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using clothsim::write_file_atomically;

namespace {

using clothsim::test::TempDir;

std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

int entries(const fs::path& dir) {
    int n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
    return n;
}

}  // namespace

TEST_CASE("atomic_file writes a new file and replaces an old one, leaving no temporary file", "[atomic_file]") {
    TempDir dir("atomic");
    const fs::path target = dir.path / "scene.toml";
    std::string error;
    REQUIRE(write_file_atomically(target, "first\n", error));
    CHECK(read(target) == "first\n");
    REQUIRE(write_file_atomically(target, "second, longer\n", error));
    CHECK(read(target) == "second, longer\n");
    CHECK(entries(dir.path) == 1);
    struct stat st {};
    REQUIRE(::stat(target.c_str(), &st) == 0);
    CHECK((st.st_mode & 0644) == 0644);  // not mkstemp's 0600: the umask decides, as for any saved file
}

TEST_CASE("atomic_file into a missing directory fails, naming the path and the directory", "[atomic_file]") {
    TempDir dir("atomic");
    const fs::path target = dir.path / "missing" / "scene.toml";
    std::string error;
    CHECK_FALSE(write_file_atomically(target, "text", error));
    CHECK_THAT(error, Contains(target.string()) && Contains("does not exist"));
    CHECK(entries(dir.path) == 0);
}

TEST_CASE("atomic_file refuses a directory or a device as the target and leaves it alone", "[atomic_file]") {
    TempDir dir("atomic");
    std::string error;
    CHECK_FALSE(write_file_atomically(dir.path, "text", error));
    CHECK_THAT(error, Contains("is a directory"));
    CHECK(fs::is_directory(dir.path));
    CHECK_FALSE(write_file_atomically("/dev/null", "text", error));
    CHECK_THAT(error, Contains("/dev/null") && Contains("not a regular file"));
    CHECK(fs::is_character_file("/dev/null"));
}

TEST_CASE("atomic_file: a write that fails half-way leaves the old file whole and no temporary file",
          "[atomic_file]") {
    TempDir dir("atomic");
    const fs::path target = dir.path / "scene.toml";
    {
        std::ofstream(target) << "the old scene\n";
    }
    // A child process with a 4 KiB file-size limit tries to write 64 KiB: write() fails with EFBIG part way.
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
        rlimit limit{4096, 4096};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        std::string error;
        const bool ok = write_file_atomically(target, std::string(65536, 'x'), error);
        const bool named = error.find(target.string()) != std::string::npos &&
                           error.find("too large") != std::string::npos;
        ::_exit(!ok && named ? 0 : 1);
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);  // the write failed and said why
    CHECK(read(target) == "the old scene\n");
    CHECK(entries(dir.path) == 1);
}
