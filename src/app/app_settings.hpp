// The app's own preferences, kept between runs beside the recent files (config_directory()/settings.toml) and
// part of no scene: the panel's width. Read once at start; written when the user changes one.
#pragma once

#include <filesystem>
#include <string>

namespace clothsim {

struct AppSettings {
    static constexpr float kMaxPanelWidth = 4096.0f;  // window coordinates: wider than any screen's half
    float panel_width;  // window coordinates at content scale 1, in [kMinPanelWidth, kMaxPanelWidth]
};

bool operator==(const AppSettings& a, const AppSettings& b);

// The settings in `file`, the defaults for every one it lacks. A missing file is the defaults, silently; a file
// that does not parse, or a field of the wrong type or out of its range, keeps that setting's default and
// says so in `warning` (the file, the line, the field and its allowed range).
AppSettings read_app_settings(const std::filesystem::path& file, std::string& warning);

// Writes every setting to `file` atomically, making its folder. Returns the error ("" when written).
std::string write_app_settings(const std::filesystem::path& file, const AppSettings& settings);

// config_directory()/settings.toml, or an empty path when there is no config folder.
std::filesystem::path app_settings_file();

}  // namespace clothsim
