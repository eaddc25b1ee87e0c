// The desktop's file dialog (zenity or kdialog as a child process, polled each frame), checked with stand-in
// dialogs: small scripts named zenity and kdialog that record their arguments and answer as the real ones do.
#include "file_dialog.hpp"

#include "app/run_process.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <thread>

using namespace clothsim;
using clothsim::test::TempDir;
using Catch::Matchers::Contains;

namespace {

// An executable script `name` in `dir`.
std::filesystem::path make_tool(const TempDir& dir, const std::string& name, const std::string& body) {
    const std::filesystem::path path = dir / name;
    std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
    std::filesystem::permissions(path, std::filesystem::perms::owner_all);
    return path;
}

// Polls until the dialog closes (at most 10 s).
DesktopDialog::Result wait_for(DesktopDialog& dialog) {
    for (int i = 0; i < 1000; ++i) {
        if (auto result = dialog.poll()) return *result;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    FAIL("the dialog never closed");
    return {};
}

// Sets an environment variable for one scope.
struct Env {
    std::string name;
    std::optional<std::string> old;
    Env(std::string n, const std::string& value) : name(std::move(n)) {
        if (const char* v = std::getenv(name.c_str())) old = v;
        ::setenv(name.c_str(), value.c_str(), 1);
    }
    ~Env() {
        if (old) ::setenv(name.c_str(), old->c_str(), 1);
        else ::unsetenv(name.c_str());
    }
};

}  // namespace

TEST_CASE("file dialog: zenity's choice comes back as the path, with the scene filter and the start folder asked for") {
    const TempDir dir("dialog_zenity");
    const auto zenity = make_tool(dir, "zenity", "printf '%s\\n' \"$@\" > \"$(dirname \"$0\")/args\"\necho /some/where/my scene.toml");
    DesktopDialog dialog;
    REQUIRE(dialog.start(dialog_command(zenity, FileDialogMode::Open, "/start/here", "")) == "");
    CHECK(dialog.running());
    const DesktopDialog::Result result = wait_for(dialog);
    CHECK(!dialog.running());
    REQUIRE(result.path);
    CHECK(*result.path == "/some/where/my scene.toml");
    CHECK(result.error.empty());
    const std::string args = clothsim::test::read_file(dir / "args");
    CHECK_THAT(args, Contains("--file-selection") && Contains("--filename=/start/here/") && Contains("*.toml"));
    CHECK_THAT(args, !Contains("--save"));
}

TEST_CASE("file dialog: saving proposes the folder and name and asks the dialog to confirm an overwrite") {
    const TempDir dir("dialog_save");
    const auto zenity = make_tool(dir, "zenity", "printf '%s\\n' \"$@\" > \"$(dirname \"$0\")/args\"\necho /x/flag-edited.toml");
    DesktopDialog dialog;
    REQUIRE(dialog.start(dialog_command(zenity, FileDialogMode::Save, "/home/me", "flag-edited.toml")) == "");
    REQUIRE(wait_for(dialog).path == std::optional<std::string>("/x/flag-edited.toml"));
    const std::string args = clothsim::test::read_file(dir / "args");
    CHECK_THAT(args, Contains("--save") && Contains("--confirm-overwrite") && Contains("--filename=/home/me/flag-edited.toml"));

    const auto kdialog = make_tool(dir, "kdialog", "printf '%s\\n' \"$@\" > \"$(dirname \"$0\")/kargs\"\necho /y/a.toml");
    REQUIRE(dialog.start(dialog_command(kdialog, FileDialogMode::Save, "/home/me", "a.toml")) == "");
    REQUIRE(wait_for(dialog).path == std::optional<std::string>("/y/a.toml"));
    CHECK(clothsim::test::read_file(dir / "kargs") ==
          "--getsavefilename\n/home/me/a.toml\n*.toml|Scene files (*.toml)\n--title\nSave scene as\n");
}

TEST_CASE("file dialog: Cancel gives no path and no error, a dialog that fails says why") {
    const TempDir dir("dialog_cancel");
    DesktopDialog dialog;
    REQUIRE(dialog.start({make_tool(dir, "zenity", "exit 1").string()}) == "");
    DesktopDialog::Result cancelled = wait_for(dialog);
    CHECK(!cancelled.path);
    CHECK(cancelled.error.empty());
    REQUIRE(dialog.start({make_tool(dir, "kdialog", "echo 'cannot open display' >&2\nexit 254").string()}) == "");
    DesktopDialog::Result failed = wait_for(dialog);
    CHECK(!failed.path);
    CHECK_THAT(failed.error, Contains("exit 254") && Contains("cannot open display"));
    // A program that is not there: said at once, nothing runs.
    CHECK_THAT(dialog.start({(dir / "no-such-dialog").string()}), Contains("no-such-dialog"));
    CHECK(!dialog.running());
}

TEST_CASE("file dialog: polling never blocks while the dialog is open, and closing the app closes the dialog") {
    const TempDir dir("dialog_open");
    const auto slow = make_tool(dir, "zenity", "sleep 30");
    const auto start = std::chrono::steady_clock::now();
    {
        DesktopDialog dialog;
        REQUIRE(dialog.start({slow.string()}) == "");
        for (int frame = 0; frame < 10; ++frame) CHECK(!dialog.poll());
        CHECK(dialog.running());
    }  // destroyed while open
    CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(10));
}

TEST_CASE("file dialog: zenity, then kdialog, from PATH, CLOTHSIM_FILE_DIALOG chooses, imgui means the built-in browser") {
    const TempDir dir("dialog_choice");
    const Env path("PATH", dir.path().string());
    const Env display("DISPLAY", ":0");
    Env choice("CLOTHSIM_FILE_DIALOG", "auto");
    CHECK(!desktop_dialog_tool());  // neither installed: the ImGui browser
    const auto kdialog = make_tool(dir, "kdialog", "exit 1");
    CHECK(desktop_dialog_tool() == kdialog);
    const auto zenity = make_tool(dir, "zenity", "exit 1");
    CHECK(desktop_dialog_tool() == zenity);
    ::setenv("CLOTHSIM_FILE_DIALOG", "kdialog", 1);
    CHECK(desktop_dialog_tool() == kdialog);
    ::setenv("CLOTHSIM_FILE_DIALOG", "imgui", 1);
    CHECK(!desktop_dialog_tool());
    // No display at all (a console, ssh without X forwarding): zenity could not show, the browser it is.
    ::setenv("CLOTHSIM_FILE_DIALOG", "auto", 1);
    const Env wayland("WAYLAND_DISPLAY", "");
    ::unsetenv("DISPLAY");
    CHECK(!desktop_dialog_tool());
}
