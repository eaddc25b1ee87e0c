// The built-in file browser's folder listing and name field (what its buttons act on), without a window.
#include "file_browser.hpp"

#include "app/run_process.hpp"

#include <catch2/catch.hpp>

#include <fstream>

using namespace clothsim;
using clothsim::test::TempDir;
using Catch::Matchers::Contains;

TEST_CASE("file browser: folders first, then .toml files, each sorted without regard to case, hidden and other files left out") {
    const TempDir dir("browser_list");
    for (const char* f : {"b.toml", "A.toml", "notes.txt", ".hidden.toml", "c.TOML.bak"}) std::ofstream(dir / f) << "x";
    for (const char* d : {"zeta", "Alpha", ".git"}) std::filesystem::create_directories(dir / d);
    FileBrowser browser;
    browser.open(FileDialogMode::Open, dir.path(), "");
    CHECK(browser.folder() == dir.path());
    CHECK(browser.entries() == std::vector<std::string>{"Alpha/", "zeta/", "A.toml", "b.toml"});
    browser.go_to(dir / "zeta");
    CHECK(browser.entries().empty());
    browser.go_to(dir / "zeta" / "..");  // shown as the plain folder
    CHECK(browser.folder() == dir.path());
}

TEST_CASE("file browser: the name field opens an existing file, goes into a folder, and says why otherwise") {
    const TempDir dir("browser_open");
    std::ofstream(dir / "a.toml") << "x";
    std::filesystem::create_directories(dir / "sub");
    FileBrowser browser;
    browser.open(FileDialogMode::Open, dir.path(), "");
    CHECK(browser.resolve("a.toml").file == std::optional(dir / "a.toml"));
    CHECK(browser.resolve((dir / "a.toml").string()).file == std::optional(dir / "a.toml"));
    CHECK(browser.resolve("sub").folder == std::optional(dir / "sub"));
    CHECK(browser.resolve("..").folder == std::optional(dir.path().parent_path()));
    const FileBrowser::Choice missing = browser.resolve("b.toml");
    CHECK(!missing.file);
    CHECK_THAT(missing.error, Contains("no such file") && Contains("b.toml"));
    CHECK_THAT(browser.resolve("").error, Contains("choose a file"));
}

TEST_CASE("file browser: saving adds .toml, and refuses a folder that does not exist") {
    const TempDir dir("browser_save");
    FileBrowser browser;
    browser.open(FileDialogMode::Save, dir.path(), "flag-edited.toml");
    CHECK(browser.resolve("flag-edited.toml").file == std::optional(dir / "flag-edited.toml"));
    CHECK(browser.resolve("mine").file == std::optional(dir / "mine.toml"));
    const FileBrowser::Choice nowhere = browser.resolve("no/such/folder/x.toml");
    CHECK(!nowhere.file);
    CHECK_THAT(nowhere.error, Contains("no such folder"));
}
