// The app's own settings (the panel's width): kept between runs, a bad file named with its line and the
// allowed range, the default kept for what it gets wrong.
#include "app_settings.hpp"

#include "app/run_process.hpp"
#include "layout.hpp"

#include <catch2/catch.hpp>

#include <fstream>

using namespace clothsim;
using clothsim::test::TempDir;
using Catch::Matchers::Contains;

namespace {

std::filesystem::path write(const TempDir& dir, const std::string& text) {
    const std::filesystem::path p = dir / "config" / "settings.toml";
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p) << text;
    return p;
}

}  // namespace

TEST_CASE("app settings: a width written is the width read, and a missing file is the defaults, silently") {
    const TempDir dir("settings_round_trip");
    const std::filesystem::path file = dir / "new-folder" / "settings.toml";
    std::string warning = "stale";
    CHECK(read_app_settings(file, warning).panel_width == kPanelWidth);
    CHECK(warning.empty());
    CHECK(write_app_settings(file, AppSettings{612.5f}) == "");
    CHECK(read_app_settings(file, warning).panel_width == 612.5f);
    CHECK(warning.empty());
    CHECK(write_app_settings(file, AppSettings{kMinPanelWidth}) == "");  // the range's ends are allowed
    CHECK(read_app_settings(file, warning).panel_width == kMinPanelWidth);
    CHECK(warning.empty());
}

TEST_CASE("app settings: a width out of range or of the wrong type keeps the default, naming file, line and range") {
    const TempDir dir("settings_range");
    for (const std::string value : {"12", "-400", "1e9", "nan", "inf", "\"wide\"", "[500]"}) {
        CAPTURE(value);
        const auto file = write(dir, "# comment\n\npanel_width = " + value + "\n");
        std::string warning;
        CHECK(read_app_settings(file, warning).panel_width == kPanelWidth);
        CHECK_THAT(warning, Contains(file.string() + ":3: panel_width") && Contains("from 300 to 4096"));
    }
}

TEST_CASE("app settings: a file that does not parse keeps the defaults, naming file and line") {
    const TempDir dir("settings_parse");
    const auto file = write(dir, "panel_width = 500\npanel_width = = 3\n");
    std::string warning;
    CHECK(read_app_settings(file, warning).panel_width == kPanelWidth);
    CHECK_THAT(warning, Contains(file.string() + ":2:") && Contains("using the default settings"));
}

TEST_CASE("app settings: a folder that cannot be made is an error returned, not thrown") {
    const TempDir dir("settings_blocked");
    std::ofstream(dir / "blocker") << "a file where the config folder should be\n";
    CHECK_THAT(write_app_settings(dir / "blocker" / "settings.toml", AppSettings{500.0f}), Contains("blocker"));
}
