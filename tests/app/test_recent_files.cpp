// The recent scene files: newest first, at most eight, no repeats, kept between runs in the config folder.
#include "recent_files.hpp"

#include "app/run_process.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>

using namespace clothsim;
using clothsim::test::TempDir;

namespace {

std::filesystem::path touch(const TempDir& dir, const std::string& name) {
    const std::filesystem::path p = dir / name;
    std::ofstream(p) << "name = \"x\"\n";
    return p;
}

}  // namespace

TEST_CASE("recent files: newest first, a file opened again moves to the front, at most eight") {
    const TempDir dir("recent_order");
    RecentFiles recent(dir / "config" / "recent-files");
    CHECK(recent.files().empty());
    for (char c = '0'; c <= '9'; ++c) CHECK(recent.add(touch(dir, std::string{'s', c, '.', 't', 'o', 'm', 'l'})) == "");
    REQUIRE(recent.files().size() == RecentFiles::kMax);
    CHECK(recent.files().front() == (dir / "s9.toml").string());
    CHECK(recent.files().back() == (dir / "s2.toml").string());
    recent.add(dir / "s5.toml");
    CHECK(recent.files().front() == (dir / "s5.toml").string());
    CHECK(std::count(recent.files().begin(), recent.files().end(), (dir / "s5.toml").string()) == 1);
    CHECK(recent.files().size() == RecentFiles::kMax);
}

TEST_CASE("recent files: the next run reads the list back, without files that are gone and without temporary files") {
    const TempDir dir("recent_persist");
    const std::filesystem::path file = dir / "config" / "recent-files";
    {
        RecentFiles recent(file);
        recent.add(touch(dir, "a.toml"));
        recent.add(touch(dir, "b.toml"));
        recent.add(touch(dir, "gone.toml"));
    }
    std::filesystem::remove(dir / "gone.toml");
    const RecentFiles next(file);
    REQUIRE(next.files().size() == 2);
    CHECK(next.files()[0] == (dir / "b.toml").string());
    CHECK(next.files()[1] == (dir / "a.toml").string());
    int entries = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir / "config")) ++entries;
    CHECK(entries == 1);  // written atomically: only the list itself
}

TEST_CASE("recent files: relative paths are stored absolute, a list that cannot be written says why and keeps working") {
    const TempDir dir("recent_relative");
    const std::filesystem::path here = std::filesystem::current_path();
    std::filesystem::current_path(dir.path());
    touch(dir, "rel.toml");
    RecentFiles recent(dir / "config" / "recent-files");
    recent.add("rel.toml");
    std::filesystem::current_path(here);
    REQUIRE(recent.files().size() == 1);
    CHECK(recent.files()[0] == (dir / "rel.toml").string());

    touch(dir, "blocker");  // a file where the config folder should be
    RecentFiles blocked(dir / "blocker" / "recent-files");
    CHECK(!blocked.add(dir / "rel.toml").empty());
    CHECK(blocked.files().size() == 1);  // still remembered for this run
}

TEST_CASE("recent files: the config folder is $XDG_CONFIG_HOME/clothsim, else ~/.config/clothsim") {
    const char* xdg = std::getenv("XDG_CONFIG_HOME");
    const std::string old_xdg = xdg ? xdg : "";
    ::setenv("XDG_CONFIG_HOME", "/tmp/xdg-test", 1);
    CHECK(config_directory() == std::filesystem::path("/tmp/xdg-test/clothsim"));
    ::setenv("XDG_CONFIG_HOME", "relative/is/ignored", 1);  // the XDG spec: only absolute paths count
    if (const char* home = std::getenv("HOME"); home && *home) {
        CHECK(config_directory() == std::filesystem::path(home) / ".config" / "clothsim");
    }
    if (xdg) ::setenv("XDG_CONFIG_HOME", old_xdg.c_str(), 1);
    else ::unsetenv("XDG_CONFIG_HOME");
}
