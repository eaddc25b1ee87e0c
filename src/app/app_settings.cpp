#include "app_settings.hpp"

#include "layout.hpp"
#include "recent_files.hpp"

#include "clothsim/atomic_file.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <sstream>
#include <system_error>

namespace clothsim {

bool operator==(const AppSettings& a, const AppSettings& b) { return a.panel_width == b.panel_width; }

AppSettings read_app_settings(const std::filesystem::path& file, std::string& warning) {
    warning.clear();
    AppSettings settings{kPanelWidth};
    std::error_code ec;
    if (file.empty() || !std::filesystem::exists(file, ec)) return settings;
    toml::table table;
    try {
        table = toml::parse_file(file.string());
    } catch (const toml::parse_error& e) {
        std::ostringstream out;
        out << file.string() << ":" << e.source().begin.line << ": " << e.description() << "; using the default settings";
        warning = out.str();
        return settings;
    }
    if (const toml::node* node = table.get("panel_width")) {
        const std::optional<double> value = node->value<double>();
        if (value && std::isfinite(*value) && *value >= kMinPanelWidth && *value <= AppSettings::kMaxPanelWidth) {
            settings.panel_width = static_cast<float>(*value);
        } else {
            std::ostringstream out;
            out << file.string() << ":" << node->source().begin.line << ": panel_width must be a number of pixels from "
                << kMinPanelWidth << " to " << AppSettings::kMaxPanelWidth << "; using " << kPanelWidth;
            warning = out.str();
        }
    }
    return settings;
}

std::string write_app_settings(const std::filesystem::path& file, const AppSettings& settings) {
    if (file.empty()) return "";
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    if (ec) return "cannot create " + file.parent_path().string() + ": " + ec.message();
    std::ostringstream text;
    text << "# clothsim's own settings (not a scene); the app rewrites this file when one changes\n"
         << "panel_width = " << settings.panel_width << "  # pixels at content scale 1, the panel's edge as dragged\n";
    std::string error;
    write_file_atomically(file, text.str(), error);
    return error;
}

std::filesystem::path app_settings_file() {
    const auto dir = config_directory();
    return dir ? *dir / "settings.toml" : std::filesystem::path();
}

}  // namespace clothsim
