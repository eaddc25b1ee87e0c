#include "recent_files.hpp"

#include "clothsim/atomic_file.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <system_error>

namespace clothsim {

std::optional<std::filesystem::path> config_directory() {
    // XDG Base Directory Specification: $XDG_CONFIG_HOME when set to an absolute path, else ~/.config.
    if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg && *xdg == '/') return std::filesystem::path(xdg) / "clothsim";
    if (const char* home = std::getenv("HOME"); home && *home) return std::filesystem::path(home) / ".config" / "clothsim";
    return std::nullopt;
}

RecentFiles::RecentFiles(std::filesystem::path file) : file_(std::move(file)) {
    if (file_.empty()) return;
    std::ifstream in(file_);
    std::string line;
    while (files_.size() < kMax && std::getline(in, line)) {
        std::error_code ec;
        if (!line.empty() && line.front() == '/' && std::filesystem::is_regular_file(line, ec) &&
            std::find(files_.begin(), files_.end(), line) == files_.end()) {
            files_.push_back(line);
        }
    }
}

RecentFiles RecentFiles::from_config() {
    const auto dir = config_directory();
    return RecentFiles(dir ? *dir / "recent-files" : std::filesystem::path());
}

std::string RecentFiles::add(const std::filesystem::path& path) {
    std::error_code ec;
    std::filesystem::path absolute = std::filesystem::absolute(path, ec);
    const std::string entry = (ec ? path : absolute.lexically_normal()).string();
    if (entry.find('\n') != std::string::npos) return "";  // one path a line: such a name is not remembered
    std::erase(files_, entry);
    files_.insert(files_.begin(), entry);
    if (files_.size() > kMax) files_.resize(kMax);
    if (file_.empty()) return "";
    std::filesystem::create_directories(file_.parent_path(), ec);
    if (ec) return "cannot create " + file_.parent_path().string() + ": " + ec.message();
    std::string text;
    for (const std::string& f : files_) text += f + "\n";
    std::string error;
    write_file_atomically(file_, text, error);
    return error;
}

}  // namespace clothsim
