// The recent scene files, newest first, remembered between runs in the user's config directory
// ($XDG_CONFIG_HOME/clothsim/recent-files, else ~/.config/clothsim/recent-files): one absolute path a line,
// written atomically (atomic_file.hpp), so a crash mid-write never loses the list.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {

// The folder clothsim keeps its settings in, or nothing when neither $XDG_CONFIG_HOME nor $HOME is set.
std::optional<std::filesystem::path> config_directory();

class RecentFiles {
public:
    static constexpr std::size_t kMax = 8;

    // Reads the list from `file` (a missing or unreadable file is an empty list; files that no longer exist
    // are left out). An empty path keeps the list in memory only.
    explicit RecentFiles(std::filesystem::path file);
    // The list at config_directory()/recent-files.
    static RecentFiles from_config();

    const std::vector<std::string>& files() const { return files_; }
    // Puts `path` (made absolute) first, drops an older entry of it and anything past kMax, and writes the
    // list. Returns the write error ("" when written, or when there is no file to write).
    std::string add(const std::filesystem::path& path);

private:
    std::filesystem::path file_;
    std::vector<std::string> files_;
};

}  // namespace clothsim
