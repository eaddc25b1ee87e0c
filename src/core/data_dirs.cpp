#include "clothsim/data_dirs.hpp"

#include <cstdlib>

namespace clothsim {

std::filesystem::path data_directory(const char* env_var, const char* built_in) {
    if (const char* dir = std::getenv(env_var); dir && *dir) return dir;
    return built_in;
}

}  // namespace clothsim
