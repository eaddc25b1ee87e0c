// The desktop's own file dialog, as the portable-file-dialogs library does it (Debian packages no
// file-dialog library): zenity (GNOME) or kdialog (KDE) run as a child process, polled each frame, so the
// window keeps drawing and simulating while the dialog is open. No GL, GLFW or ImGui here; when neither tool
// is installed the app falls back to its ImGui file browser (file_browser.hpp).
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {

enum class FileDialogMode { Open, Save };

// Which dialog to use: $CLOTHSIM_FILE_DIALOG = "zenity", "kdialog" or "imgui" chooses; unset (or "auto")
// takes zenity, else kdialog, from $PATH. Returns the tool's path, or nothing for the ImGui browser (also
// when neither $DISPLAY nor $WAYLAND_DISPLAY is set: no desktop to show a dialog on).
std::optional<std::filesystem::path> desktop_dialog_tool();

// The command line that asks `tool` (zenity or kdialog, by its file name) for a scene file: to open, starting
// in `folder`, or to save, proposing `folder`/`file_name` (overwriting is confirmed by the dialog).
std::vector<std::string> dialog_command(const std::filesystem::path& tool, FileDialogMode mode,
                                        const std::filesystem::path& folder, const std::string& file_name);

// One dialog run as a child process. Destroying it while it runs closes the dialog (SIGTERM).
class DesktopDialog {
public:
    struct Result {
        std::optional<std::string> path;  // the chosen file; nothing when cancelled or failed
        std::string error;                // why it failed (the tool's own message), "" when it did not
    };

    DesktopDialog() = default;
    ~DesktopDialog();
    DesktopDialog(const DesktopDialog&) = delete;
    DesktopDialog& operator=(const DesktopDialog&) = delete;

    // Starts `command` (argv; argv[0] a path); returns the error, or "" when it runs.
    std::string start(const std::vector<std::string>& command);
    bool running() const { return pid_ > 0; }
    // Nothing while the dialog is open; its result once, when it has closed.
    std::optional<Result> poll();

private:
    void drain();
    pid_t pid_ = -1;
    int out_ = -1, err_ = -1;  // the child's stdout and stderr (read ends, non-blocking)
    std::string out_text_, err_text_;
};

}  // namespace clothsim
