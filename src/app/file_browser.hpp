// The built-in file browser (Dear ImGui), for desktops without zenity or kdialog (file_dialog.hpp): a modal
// window listing a folder's subfolders and .toml files, with shortcuts to the bundled scenes, the home folder
// and the working folder, a file-name field, and Open / Save and Cancel. Saving over a file asks first.
#pragma once

#include "file_dialog.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {

class FileBrowser {
public:
    // Shows the browser from the next frame: in `folder`, with `file_name` in the name field (Save).
    void open(FileDialogMode mode, const std::filesystem::path& folder, const std::string& file_name);
    bool is_open() const { return open_; }
    FileDialogMode mode() const { return mode_; }
    // Draws it while open (between ImGui::NewFrame and ImGui::Render); returns the chosen file once, when the
    // user presses Open or Save (or Return in the name field, or double-clicks a file). Escape or Cancel
    // closes it with nothing chosen.
    std::optional<std::string> draw(float scale);

    // What the name field's text means in the current folder: the file to open or save, a folder to go
    // into, or a message saying why neither (exposed for the tests).
    struct Choice {
        std::optional<std::filesystem::path> file, folder;
        std::string error;
    };
    Choice resolve(const std::string& name) const;
    void go_to(const std::filesystem::path& folder);
    const std::filesystem::path& folder() const { return folder_; }
    // The current folder's entries as listed: subfolders first (name + "/"), then .toml files, each sorted.
    const std::vector<std::string>& entries() const { return entries_; }

private:
    FileDialogMode mode_ = FileDialogMode::Open;
    bool open_ = false, opening_ = false;
    std::filesystem::path folder_;
    std::string name_, error_;
    std::vector<std::string> entries_;
    std::optional<std::filesystem::path> confirm_;  // Save over this existing file? (asked first)
};

}  // namespace clothsim
