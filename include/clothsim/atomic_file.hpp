// Writing a file so that it is either the old file or the complete new one, never half of either: the
// text goes to a temporary file beside the target, is flushed to disk, and is renamed over the target
// (rename(2) replaces a file atomically on POSIX file systems). Used for "Save scene" and the OBJ export.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace clothsim {

// Returns false with `error` naming the path and the reason (the directory does not exist, the target is a
// directory or a device, the disk is full, a file-size limit); the old file, if any, is then untouched and
// no temporary file is left behind.
bool write_file_atomically(const std::filesystem::path& path, std::string_view text, std::string& error);

}  // namespace clothsim
