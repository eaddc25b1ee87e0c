// The programs that make the bundled assets (src/tools): clothsim-make-meshes and clothsim-make-textures, run as
// a developer runs them. A flag is answered, never taken for the folder to write into.
#include "../app/run_process.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;
using clothsim::test::quote;
using clothsim::test::read_file;
using clothsim::test::run_process;
using clothsim::test::TempDir;

const fs::path kSource = CLOTHSIM_SOURCE_DIR;

// Runs `exe args` with `dir` as the working directory.
clothsim::test::RunResult run_in(const fs::path& dir, const std::string& exe, const std::vector<std::string>& args) {
    return run_process(exe, args, "cd " + quote(dir.string()) + " &&");
}

}  // namespace

TEST_CASE("asset tools: --help prints the usage and writes nothing, an unknown option exits 2 naming it") {
    for (const std::string exe : {CLOTHSIM_MAKE_MESHES, CLOTHSIM_MAKE_TEXTURES}) {
        const std::string name = fs::path(exe).filename().string();
        INFO(name);
        TempDir cwd("asset_tools_" + name);
        const auto help = run_in(cwd.path(), exe, {"--help"});
        CAPTURE_RUN(help);
        CHECK(help.code == 0);
        CHECK_THAT(help.out, Catch::StartsWith("usage: " + name + " "));
        const auto bogus = run_in(cwd.path(), exe, {"--bogus"});
        CAPTURE_RUN(bogus);
        CHECK(bogus.code == 2);
        CHECK_THAT(bogus.err, Catch::Contains(name + ": unknown option --bogus") && Catch::Contains("usage: " + name));
        const auto none = run_in(cwd.path(), exe, {});
        CHECK(none.code == 2);
        CHECK_THAT(none.err, Catch::Contains("usage: " + name));
        // Nothing was written: no folder named after a flag, nothing at all.
        CHECK(fs::is_empty(cwd.path()));
    }
}

TEST_CASE("asset tools: clothsim-make-meshes writes the bundled meshes byte for byte") {
    TempDir out("asset_tools_meshes");
    const auto run = run_process(CLOTHSIM_MAKE_MESHES, {(out / "meshes").string()});
    CAPTURE_RUN(run);
    REQUIRE(run.code == 0);
    int files = 0;
    for (const auto& entry : fs::directory_iterator(kSource / "assets" / "meshes")) {
        INFO(entry.path().filename().string());
        const fs::path made = out / "meshes" / entry.path().filename();
        REQUIRE(fs::exists(made));
        CHECK(read_file(made) == read_file(entry.path()));
        ++files;
    }
    CHECK(files == 8);
}
