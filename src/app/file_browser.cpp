#include "file_browser.hpp"

#include "clothsim/scene.hpp"

#include <imgui.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <system_error>

namespace clothsim {
namespace {

const char* title(FileDialogMode mode) { return mode == FileDialogMode::Save ? "Save scene as###browser" : "Open scene file###browser"; }

bool less_ignoring_case(const std::string& a, const std::string& b) {
    return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end(), [](unsigned char x, unsigned char y) {
        return std::tolower(x) < std::tolower(y);
    });
}

// The path in its plain form: no ".", "..", or trailing '/' (lexically_normal leaves one after "..").
std::filesystem::path tidy(const std::filesystem::path& path) {
    std::filesystem::path p = path.lexically_normal();
    if (!p.has_filename() && p != p.root_path()) p = p.parent_path();
    return p;
}

}  // namespace

void FileBrowser::open(FileDialogMode mode, const std::filesystem::path& folder, const std::string& file_name) {
    mode_ = mode;
    open_ = opening_ = true;
    name_ = file_name;
    confirm_.reset();
    go_to(folder);
}

void FileBrowser::go_to(const std::filesystem::path& folder) {
    std::error_code ec;
    std::filesystem::path absolute = std::filesystem::absolute(folder, ec);
    folder_ = tidy(ec ? folder : absolute);
    entries_.clear();
    error_.clear();
    std::vector<std::string> folders, files;
    std::filesystem::directory_iterator it(folder_, std::filesystem::directory_options::skip_permission_denied, ec);
    // The error_code forms throughout: a folder removed or unreadable mid-listing is a message, not a throw.
    for (; !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.empty() || name.front() == '.') continue;  // hidden, as every desktop file dialog hides them
        std::error_code e;
        if (it->is_directory(e)) folders.push_back(name + "/");
        else if (it->path().extension() == ".toml") files.push_back(name);
    }
    if (ec) error_ = "cannot read " + folder_.string() + ": " + ec.message();
    std::sort(folders.begin(), folders.end(), less_ignoring_case);
    std::sort(files.begin(), files.end(), less_ignoring_case);
    entries_ = std::move(folders);
    entries_.insert(entries_.end(), files.begin(), files.end());
}

FileBrowser::Choice FileBrowser::resolve(const std::string& name) const {
    Choice choice;
    if (name.empty()) {
        choice.error = mode_ == FileDialogMode::Save ? "type a file name" : "choose a file";
        return choice;
    }
    std::filesystem::path path = name;
    if (name.front() == '~') {
        if (const char* home = std::getenv("HOME")) path = std::string(home) + name.substr(1);
    }
    if (path.is_relative()) path = folder_ / path;
    path = tidy(path);
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        choice.folder = path;
        return choice;
    }
    if (mode_ == FileDialogMode::Open) {
        if (!std::filesystem::is_regular_file(path, ec)) choice.error = "no such file: " + path.string();
        else choice.file = path;
        return choice;
    }
    if (path.extension() != ".toml") path += ".toml";  // scene files end in .toml
    if (!std::filesystem::is_directory(path.parent_path(), ec)) {
        choice.error = "no such folder: " + path.parent_path().string();
    } else {
        choice.file = path;
    }
    return choice;
}

std::optional<std::string> FileBrowser::draw(float scale) {
    if (!open_) return std::nullopt;
    const char* id = title(mode_);
    if (opening_) {
        ImGui::OpenPopup(id);
        opening_ = false;
    }
    const ImGuiViewport* viewport = ImGui::GetMainViewport();
    ImGui::SetNextWindowPos(ImVec2(viewport->WorkPos.x + viewport->WorkSize.x * 0.5f, viewport->WorkPos.y + viewport->WorkSize.y * 0.5f),
                            ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSize(ImVec2(std::min(620.0f * scale, viewport->WorkSize.x), std::min(440.0f * scale, viewport->WorkSize.y)),
                             ImGuiCond_Appearing);
    bool keep = true;
    if (!ImGui::BeginPopupModal(id, &keep, ImGuiWindowFlags_NoSavedSettings)) {
        open_ = false;
        return std::nullopt;
    }
    std::optional<std::string> chosen;
    auto close = [&] {
        open_ = false;
        ImGui::CloseCurrentPopup();
    };
    auto accept = [&](const std::string& name) {
        const Choice c = resolve(name);
        error_ = c.error;
        if (c.folder) {
            go_to(*c.folder);
            if (!error_.empty()) return;
            if (name.find('/') != std::string::npos || name == "..") name_.clear();
        } else if (c.file) {
            std::error_code ec;
            if (mode_ == FileDialogMode::Save && std::filesystem::exists(*c.file, ec)) {
                confirm_ = *c.file;
            } else {
                chosen = c.file->string();
                close();
            }
        }
    };

    // Shortcuts, and where we are.
    if (ImGui::Button("Up")) go_to(folder_.parent_path());
    ImGui::SameLine();
    if (ImGui::Button("Bundled scenes")) go_to(scene_directory());
    ImGui::SameLine();
    if (ImGui::Button("Home")) {
        if (const char* home = std::getenv("HOME")) go_to(home);
    }
    ImGui::SameLine();
    if (ImGui::Button("Working folder")) {
        std::error_code ec;
        const std::filesystem::path here = std::filesystem::current_path(ec);
        if (ec) error_ = "the working folder is gone: " + ec.message();
        else go_to(here);
    }
    ImGui::TextWrapped("%s", folder_.c_str());

    // The folder's entries: a click on a folder goes into it; a click on a file puts its name in the field,
    // a double-click takes it.
    const float footer = ImGui::GetFrameHeightWithSpacing() * 2.0f + ImGui::GetTextLineHeightWithSpacing() * 2.0f;
    ImGui::BeginChild("entries", ImVec2(0.0f, -footer), true);
    if (entries_.empty()) ImGui::TextDisabled("no folders or .toml files here");
    std::optional<std::string> into, take;
    for (const std::string& entry : entries_) {
        const bool is_folder = entry.back() == '/';
        if (ImGui::Selectable(entry.c_str(), !is_folder && entry == name_, ImGuiSelectableFlags_AllowDoubleClick)) {
            if (is_folder) into = entry;
            else {
                name_ = entry;
                if (ImGui::IsMouseDoubleClicked(0)) take = entry;
            }
        }
    }
    ImGui::EndChild();
    if (into) {
        go_to(folder_ / *into);
    }
    if (take) accept(*take);

    // The name field and the buttons; Return in the field is the Open / Save button.
    char text[1024];
    std::snprintf(text, sizeof text, "%s", name_.c_str());
    ImGui::SetNextItemWidth(-ImGui::GetFontSize() * 6.0f);
    if (ImGui::IsWindowAppearing()) ImGui::SetKeyboardFocusHere();
    const bool entered = ImGui::InputText("file name", text, sizeof text, ImGuiInputTextFlags_EnterReturnsTrue);
    name_ = text;
    if (confirm_) {
        ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.4f, 1.0f), "%s exists. Replace it?", confirm_->filename().c_str());
        if (ImGui::Button("Replace")) {
            chosen = confirm_->string();
            confirm_.reset();
            close();
        }
        ImGui::SameLine();
        if (ImGui::Button("Keep it")) confirm_.reset();
    } else {
        if (!error_.empty()) ImGui::TextColored(ImVec4(1.0f, 0.45f, 0.4f, 1.0f), "%s", error_.c_str());
        else ImGui::TextDisabled("%s", mode_ == FileDialogMode::Save ? "scene files end in .toml" : "scene files (.toml)");
        // Return acts wherever the keyboard is, as in a desktop dialog (also before the field has the focus).
        const bool enter = ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Enter), false);
        if (ImGui::Button(mode_ == FileDialogMode::Save ? "Save" : "Open") || entered || enter) accept(name_);
        ImGui::SameLine();
        if (ImGui::Button("Cancel")) close();
    }
    if (open_ && ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) close();
    if (!keep) open_ = false;  // the title bar's close button
    ImGui::EndPopup();
    return chosen;
}

}  // namespace clothsim
