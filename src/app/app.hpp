// The desktop app: a window, the renderer and the settings panel around one MassSpring.
#pragma once

#include "renderer.hpp"

#include "clothsim/settings.hpp"

#include <glm/vec2.hpp>

#include <filesystem>
#include <optional>
#include <string>

namespace clothsim {

struct AppOptions {
    std::string scene_source = "hanging";  // bundled name or path, shown in the panel
    glm::ivec2 size{1280, 720};            // window size in screen coordinates
    // Scripted rendering: run exactly `frames` frames (one step of integration.dt each, whatever the wall
    // clock says), write the last one to `screenshot` (panel included) and exit.
    std::optional<long long> frames;
    std::string screenshot;
    // With `frames`: every frame written as record/frame-000001.png, ... (--record).
    std::string record;
    // Interactive runs: start paused (--paused; nothing is stepped until Play, Space or S), and end after
    // this many wall seconds as if the window were closed (--quit-after; exit code 0).
    bool start_paused = false;
    std::optional<double> quit_after;
    // A CSV row per frame as it ends (--frame-times, frame_log.hpp): its costs and the cloth's state, so
    // a script can measure what the window costs (docs/PERFORMANCE.md, "Threads under load").
    std::string frame_times;
    ViewSettings view;       // the View section's start values (--view)
    int samples = -1;        // anti-aliasing samples per pixel (--samples; -1: 4, none on a software renderer)
    bool show_panel = true;
    // Auto substeps (on in interactive runs; scripted runs step exactly what the scene says unless asked).
    bool auto_substeps = true;
    float safety = 0.5f;
};

// Applies one --view item ("wireframe", "springs=strain", "no-shadows", ...); false if unknown.
bool apply_view_option(ViewSettings& view, bool& show_panel, const std::string& item);

// Returns the process exit code: 0; 2 when there is no window / OpenGL 3.3 / shader / texture / screenshot
// file; 4 when a scripted run (--frames) hit an OpenGL error.
int run_app(const Scene& scene, const AppOptions& options);

// Writes the current back buffer (RGBA, bottom-up) as PNG; returns an error message or "".
std::string write_screenshot(const std::string& path, int width, int height);

// --record's folder: created when missing; refused (the message) when it already holds a recording's
// frames, which would mix with the new ones. "" when ready.
std::string prepare_record_folder(const std::filesystem::path& folder);

// "clothsim-20261124-101530.png": screenshots taken with F12.
std::string timestamped_screenshot_name();

}  // namespace clothsim
