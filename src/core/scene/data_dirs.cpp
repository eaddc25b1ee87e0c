#include "clothsim/data_dirs.hpp"

#include <cstdlib>
#include <system_error>

namespace clothsim {

std::filesystem::path executable_path() {
    std::error_code ec;
    std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::filesystem::path() : exe;
}

std::filesystem::path data_directory(const char* env_var, std::string_view kind,
                                     const std::filesystem::path& executable) {
    if (const char* dir = std::getenv(env_var); dir && *dir) return dir;
    const std::filesystem::path data = std::filesystem::path("share") / "clothsim" / kind;
    if (executable.empty()) return "/usr" / data;  // the system does not say where we are: the .deb's place
    const std::filesystem::path exe_dir = executable.parent_path();
    std::filesystem::path dir = exe_dir;
    for (int up = 0; up <= 2; ++up, dir = dir.parent_path()) {
        std::error_code ec;
        if (std::filesystem::is_directory(dir / data, ec)) return dir / data;
        if (!dir.has_relative_path()) break;  // at the root: nothing above
    }
    return (exe_dir / ".." / data).lexically_normal();
}

std::filesystem::path data_directory(const char* env_var, std::string_view kind) {
    return data_directory(env_var, kind, executable_path());
}

}  // namespace clothsim
