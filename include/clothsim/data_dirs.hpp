// Where clothsim finds its data files (scenes, shaders, textures): the folder an environment variable
// names, so a moved or installed build can be pointed at its data, else the folder built in at compile time
// (the source tree's).
#pragma once

#include <filesystem>

namespace clothsim {

// $env_var when it is set and not empty, else `built_in`.
std::filesystem::path data_directory(const char* env_var, const char* built_in);

}  // namespace clothsim
