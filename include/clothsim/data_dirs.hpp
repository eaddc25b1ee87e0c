// Where clothsim finds its data files (scenes, shaders, textures): relative to its own executable, so the
// build tree, an installed tree (cmake --install, the .deb) and a moved copy of either all work; an
// environment variable overrides each kind.
#pragma once

#include <filesystem>
#include <string_view>

namespace clothsim {

// The running program's file (/proc/self/exe), or an empty path when the system does not say.
std::filesystem::path executable_path();

// The folder of data of one kind ("scenes", "shaders" or "textures"):
// - $env_var when it is set and not empty;
// - else share/clothsim/<kind> in the executable's folder or in one of the two folders above it, the first
//   that exists: <prefix>/bin/clothsim finds <prefix>/share/clothsim (GNUInstallDirs), and a build tree's
//   programs (build/release/src/clothsim, build/release/tests/fuzz/fuzz_scene) find build/release/share/clothsim,
//   which the build fills;
// - else <executable folder>/../share/clothsim/<kind>, where an installed tree would have it, so a message
//   about a missing file names the place it is expected (/usr/share/clothsim/<kind>, the package's, when
//   the executable's path is unknown).
std::filesystem::path data_directory(const char* env_var, std::string_view kind);

// The same search from a given executable path (what the tests use).
std::filesystem::path data_directory(const char* env_var, std::string_view kind,
                                     const std::filesystem::path& executable);

}  // namespace clothsim
