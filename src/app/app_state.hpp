// Everything the desktop app keeps between frames, passed explicitly (no globals): the scene being edited,
// the running simulation, the camera, view toggles and the figures the Stats section shows.
#pragma once

#include "camera.hpp"
#include "renderer.hpp"
#include "scene_loading.hpp"

#include "clothsim/mass_spring.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"
#include "clothsim/stepper.hpp"

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {

// A fixed-length history for ImGui::PlotLines.
struct History {
    static constexpr std::size_t kLength = 300;  // about 5 s at 60 frames per second
    std::array<float, kLength> values{};
    std::size_t next = 0;
    std::size_t count = 0;
    void push(float v) {
        values[next] = v;
        next = (next + 1) % kLength;
        count = std::min(count + 1, kLength);
    }
    void clear() { next = count = 0; }
    // PlotLines reads a ring buffer through its values_offset argument.
    int offset() const { return count < kLength ? 0 : static_cast<int>(next); }
    int size() const { return static_cast<int>(count); }
    float last() const { return count ? values[(next + kLength - 1) % kLength] : 0.0f; }
};

// Per-stage milliseconds per frame, smoothed over about ten frames so the panel's figures can be read.
struct StageTimes {
    static constexpr float kSmoothing = 0.1f;
    std::array<float, kStageCount> stage_ms{};
    float normals_ms = 0.0f, upload_ms = 0.0f;
    void add_frame(const StepProfile& frame, float normals, float upload) {
        for (std::size_t i = 0; i < kStageCount; ++i) {
            stage_ms[i] += kSmoothing * (static_cast<float>(frame.ms[i]) - stage_ms[i]);
        }
        normals_ms += kSmoothing * (normals - normals_ms);
        upload_ms += kSmoothing * (upload - upload_ms);
    }
};

struct Stats {
    float sim_ms = 0.0f;     // wall time of this frame's physics
    float render_ms = 0.0f;  // CPU time to issue this frame's drawing (scene and panel)
    long long substeps_last_frame = 0;
    double dropped_seconds = 0.0;  // simulated time skipped because frames were too slow to catch up
    History kinetic, potential, total;
    StepProfile profile;     // this frame's stages (MassSpring::profile, reset every frame)
    StageTimes times;
    bool cloth_uploaded = false;  // the renderer uploaded positions and normals this frame
};

// A particle held with the mouse: pinned while held and moved in the plane facing the camera.
struct Grab {
    std::size_t particle = 0;
    bool was_pinned = false;
    glm::vec3 plane_point{0.0f};
    glm::vec3 plane_normal{0.0f, 0.0f, 1.0f};
};

struct AppState {
    // The document: name, cloth and pins as edited, what Reset returns to (`loaded`). The live settings are
    // the simulation's alone; document() joins the two into what "Save scene as" writes.
    Scene scene;
    Scene loaded;             // the scene as loaded (after --set): "reset to scene value" and R go back here
    std::string scene_source; // bundled name or path it came from
    MassSpring sim;           // the running cloth; owns the live settings (MassSpring::apply)
    Stepper stepper;          // the run policy: fixed step, catch-up cap, auto substeps, the guard
    OrbitCamera camera;
    ViewSettings view;
    bool paused = false;
    bool step_once = false;
    float time_scale = 1.0f;   // simulated seconds per wall second
    bool show_panel = true;
    bool vsync = true;
    Stats stats;
    std::optional<Grab> grab;
    std::string status;        // the last message for the user (errors, screenshot path)
    bool status_is_error = false;
    std::string open_path;     // the panel's "Open scene file" text
    std::string save_path;     // the panel's "Save scene as" text

    AppState(const Scene& s, std::string source, const RunPolicy& policy)
        : scene(s), loaded(s), scene_source(std::move(source)), sim(build_simulation(s)), stepper(policy) {}

    // The scene as it runs: the document with the simulation's live settings (what Save writes).
    Scene document() const { return running_scene(scene, sim); }

    void say(std::string message, bool error = false) {
        status = std::move(message);
        status_is_error = error;
    }
};

// What the panel asks the app to do after this frame.
struct PanelRequests {
    bool rebuild = false;       // cloth or pins changed
    bool reset = false;         // back to the loaded scene's start
    bool frame_camera = false;
    bool reset_camera = false;
    bool screenshot = false;
    bool quit = false;
    std::optional<std::string> load;  // a bundled scene name or a path
    std::optional<std::string> save;  // a path
};

// Draws the settings panel and edits `app` through it (Dear ImGui).
PanelRequests draw_panel(AppState& app, float content_scale);

// Width of the panel in window coordinates (0 when hidden): the 3D view takes the rest of the window.
float panel_width(const AppState& app, float content_scale);

}  // namespace clothsim
