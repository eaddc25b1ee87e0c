#include "file_dialog.hpp"

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <system_error>
#include <unistd.h>

extern char** environ;

namespace clothsim {
namespace {

// `name` in a folder of $PATH, executable; or nothing.
std::optional<std::filesystem::path> on_path(const char* name) {
    const char* path = std::getenv("PATH");
    if (!path) return std::nullopt;
    std::string_view rest(path);
    while (!rest.empty()) {
        const std::size_t colon = rest.find(':');
        const std::string_view dir = rest.substr(0, colon);
        if (!dir.empty()) {
            const std::filesystem::path candidate = std::filesystem::path(dir) / name;
            std::error_code ec;
            if (std::filesystem::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate;
        }
        if (colon == std::string_view::npos) break;
        rest.remove_prefix(colon + 1);
    }
    return std::nullopt;
}

}  // namespace

std::optional<std::filesystem::path> desktop_dialog_tool() {
    const char* choice = std::getenv("CLOTHSIM_FILE_DIALOG");
    const std::string want = choice ? choice : "";
    if (want == "imgui") return std::nullopt;
    // Without a display for it (zenity then exits 1, as for Cancel) the dialog could never show.
    const char* x11 = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if (!(x11 && *x11) && !(wayland && *wayland)) return std::nullopt;
    if (want == "zenity" || want == "kdialog") return on_path(want.c_str());
    if (auto zenity = on_path("zenity")) return zenity;
    return on_path("kdialog");
}

std::vector<std::string> dialog_command(const std::filesystem::path& tool, FileDialogMode mode,
                                        const std::filesystem::path& folder, const std::string& file_name) {
    const bool save = mode == FileDialogMode::Save;
    const std::string start = save ? (folder / file_name).string() : (folder.string() + "/");
    if (tool.filename() == "kdialog") {
        return {tool.string(), save ? "--getsavefilename" : "--getopenfilename", start, "*.toml|Scene files (*.toml)",
                "--title", save ? "Save scene as" : "Open scene file"};
    }
    std::vector<std::string> command = {tool.string(), "--file-selection", "--title=" + std::string(save ? "Save scene as" : "Open scene file"),
                                        "--filename=" + start, "--file-filter=Scene files (*.toml) | *.toml",
                                        "--file-filter=All files | *"};
    if (save) {
        command.push_back("--save");
        command.push_back("--confirm-overwrite");
    }
    return command;
}

DesktopDialog::~DesktopDialog() {
    if (pid_ > 0) {
        ::kill(pid_, SIGTERM);
        ::waitpid(pid_, nullptr, 0);
    }
    if (out_ >= 0) ::close(out_);
    if (err_ >= 0) ::close(err_);
}

std::string DesktopDialog::start(const std::vector<std::string>& command) {
    if (pid_ > 0) return "a file dialog is already open";
    int out[2], err[2];
    if (::pipe2(out, O_CLOEXEC) != 0) return std::string("cannot start the file dialog: ") + std::strerror(errno);
    if (::pipe2(err, O_CLOEXEC) != 0) {
        ::close(out[0]);
        ::close(out[1]);
        return std::string("cannot start the file dialog: ") + std::strerror(errno);
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, err[1], STDERR_FILENO);
    std::vector<char*> argv;
    for (const std::string& a : command) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = -1;
    const int failed = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    ::close(err[1]);
    if (failed != 0) {
        ::close(out[0]);
        ::close(err[0]);
        return "cannot start " + command[0] + ": " + std::strerror(failed);
    }
    pid_ = pid;
    out_ = out[0];
    err_ = err[0];
    ::fcntl(out_, F_SETFL, O_NONBLOCK);
    ::fcntl(err_, F_SETFL, O_NONBLOCK);
    out_text_.clear();
    err_text_.clear();
    return "";
}

void DesktopDialog::drain() {
    char buffer[4096];
    for (auto [fd, text] : {std::pair{out_, &out_text_}, std::pair{err_, &err_text_}}) {
        while (fd >= 0) {
            const ssize_t n = ::read(fd, buffer, sizeof buffer);
            if (n <= 0) break;
            text->append(buffer, static_cast<std::size_t>(n));
        }
    }
}

std::optional<DesktopDialog::Result> DesktopDialog::poll() {
    if (pid_ <= 0) return std::nullopt;
    drain();
    int status = 0;
    const pid_t done = ::waitpid(pid_, &status, WNOHANG);
    if (done == 0) return std::nullopt;  // still open
    drain();
    pid_ = -1;
    ::close(out_);
    ::close(err_);
    out_ = err_ = -1;
    Result result;
    while (!out_text_.empty() && (out_text_.back() == '\n' || out_text_.back() == '\r')) out_text_.pop_back();
    while (!err_text_.empty() && err_text_.back() == '\n') err_text_.pop_back();
    const int code = done < 0 ? -1 : WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (code == 0 && !out_text_.empty()) {
        result.path = out_text_;
    } else if (code != 1) {  // 1: the user cancelled (zenity and kdialog alike)
        result.error = "the file dialog failed (exit " + std::to_string(code) + ")" + (err_text_.empty() ? "" : ": " + err_text_);
    }
    return result;
}

}  // namespace clothsim
