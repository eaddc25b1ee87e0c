// data_directory: an environment variable's folder, else share/clothsim/<kind> found from the executable
// (an installed tree, a build tree), else where an installed tree would have it.
#include "clothsim/data_dirs.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <unistd.h>

namespace fs = std::filesystem;
using clothsim::data_directory;

namespace {

// A fresh folder under the system's temporary one, removed at the end of the test.
struct TempTree {
    fs::path root = fs::temp_directory_path() / ("clothsim-data-dirs-" + std::to_string(::getpid()));
    TempTree() {
        fs::remove_all(root);
        fs::create_directories(root);
    }
    ~TempTree() { fs::remove_all(root); }
};

}  // namespace

TEST_CASE("data_directory: the variable when it is set and not empty wins over every folder", "[data_dirs]") {
    const char* name = "CLOTHSIM_TEST_DATA_DIRECTORY";
    TempTree t;
    fs::create_directories(t.root / "share/clothsim/scenes");
    ::setenv(name, "/somewhere/else", 1);
    CHECK(data_directory(name, "scenes", t.root / "bin/clothsim") == "/somewhere/else");
    ::setenv(name, "", 1);  // empty is unset
    CHECK(data_directory(name, "scenes", t.root / "bin/clothsim") == t.root / "share/clothsim/scenes");
    ::unsetenv(name);
}

TEST_CASE("data_directory: an installed program finds PREFIX/share/clothsim from PREFIX/bin", "[data_dirs]") {
    TempTree t;
    fs::create_directories(t.root / "usr/bin");
    fs::create_directories(t.root / "usr/share/clothsim/shaders");
    CHECK(data_directory("CLOTHSIM_TEST_UNSET", "shaders", t.root / "usr/bin/clothsim") ==
          t.root / "usr/share/clothsim/shaders");
}

TEST_CASE("data_directory: programs one or two folders down a build tree find its share/clothsim", "[data_dirs]") {
    TempTree t;
    fs::create_directories(t.root / "build/share/clothsim/textures");
    CHECK(data_directory("CLOTHSIM_TEST_UNSET", "textures", t.root / "build/src/clothsim") ==
          t.root / "build/share/clothsim/textures");
    CHECK(data_directory("CLOTHSIM_TEST_UNSET", "textures", t.root / "build/tests/fuzz/fuzz_scene") ==
          t.root / "build/share/clothsim/textures");
    // Beside the program counts too (a portable folder: clothsim and share/ side by side).
    fs::create_directories(t.root / "portable/share/clothsim/textures");
    CHECK(data_directory("CLOTHSIM_TEST_UNSET", "textures", t.root / "portable/clothsim") ==
          t.root / "portable/share/clothsim/textures");
    // Three folders down is too far: the search never wanders up a user's home.
    CHECK(data_directory("CLOTHSIM_TEST_UNSET", "textures", t.root / "build/a/b/c/program") ==
          t.root / "build/a/b/share/clothsim/textures");
}

TEST_CASE("data_directory: with nothing found it names where an installed tree would have the data", "[data_dirs]") {
    TempTree t;
    CHECK(data_directory("CLOTHSIM_TEST_UNSET", "scenes", t.root / "bin/clothsim") ==
          t.root / "share/clothsim/scenes");
    CHECK(data_directory("CLOTHSIM_TEST_UNSET", "scenes", "/clothsim") == "/share/clothsim/scenes");
    // Where the program is, unknown: the place the package installs to (never a folder relative to the
    // working directory).
    CHECK(data_directory("CLOTHSIM_TEST_UNSET", "scenes", "") == "/usr/share/clothsim/scenes");
}

TEST_CASE("data_directory: this test program finds the build tree's scenes", "[data_dirs]") {
    const fs::path scenes = data_directory("CLOTHSIM_TEST_UNSET", "scenes");
    CHECK(fs::exists(scenes / "hanging.toml"));
    CHECK(clothsim::executable_path().filename() == "test_core");
}
