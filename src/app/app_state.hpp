// Everything the desktop app keeps between frames, passed explicitly (no globals): the scene being edited,
// the running simulation, the camera, view toggles and the figures the Stats section shows.
#pragma once

#include "camera.hpp"
#include "layout.hpp"
#include "file_browser.hpp"
#include "file_dialog.hpp"
#include "app_settings.hpp"
#include "recent_files.hpp"
#include "renderer.hpp"
#include "scene_loading.hpp"

#include "clothsim/mass_spring.hpp"

#include <glm/vec2.hpp>
#include "clothsim/scene.hpp"
#include "clothsim/settle.hpp"
#include "clothsim/stability.hpp"
#include "clothsim/stepper.hpp"

#include <array>
#include <chrono>
#include <deque>
#include <filesystem>
#include <iostream>
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
    float frame_ms = 0.0f;   // wall time from the last frame's start to this one's
    float sim_ms = 0.0f;     // wall time of this frame's physics
    float render_ms = 0.0f;  // CPU time to issue this frame's drawing (scene and panel)
    long long substeps_last_frame = 0;
    // How fast the simulation keeps up while it plays: simulated seconds per wall second over the last
    // half second or more (the time scale when it keeps up), and the sums of the window being measured.
    float speed = 1.0f;
    double window_wall = 0.0, window_simulated = 0.0;
    History kinetic, potential, total;
    StepProfile profile;     // this frame's stages (MassSpring::profile, reset every frame)
    StageTimes times;
    bool cloth_uploaded = false;  // the renderer uploaded positions and normals this frame
};

// The panel's message area: the latest messages, newest last. Notes expire after 8 s, errors after 30 s,
// and at most 20 are kept, so the area never grows; the panel shows it at a fixed height.
struct Messages {
    using Clock = std::chrono::steady_clock;
    struct Message {
        std::string text;
        bool error = false;
        Clock::time_point expires;
    };
    static constexpr std::size_t kMax = 20;
    std::deque<Message> list;

    // Returns false when it repeats the newest message (which then only lives longer).
    bool add(std::string text, bool error) {
        while (!text.empty() && text.back() == '\n') text.pop_back();
        const auto expires = Clock::now() + std::chrono::seconds(error ? 30 : 8);
        if (!list.empty() && list.back().text == text && list.back().error == error) {
            list.back().expires = expires;  // said again (a widget still being typed into): one line
            return false;
        }
        list.push_back({std::move(text), error, expires});
        while (list.size() > kMax) list.pop_front();
        return true;
    }
    void expire() {
        const auto now = Clock::now();
        std::erase_if(list, [&](const Message& m) { return m.expires <= now; });
    }
    void clear() { list.clear(); }
};

// A particle held with the mouse, moved in the plane facing the camera: a free one through the grab spring
// (MassSpring::grab), a pinned one by moving the pin.
struct Grab {
    std::size_t particle = 0;
    bool was_pinned = false;
    glm::vec3 plane_point{0.0f};
    glm::vec3 plane_normal{0.0f, 0.0f, 1.0f};
};

// An object being moved (alt + left-drag): collider `collider`, picked at `plane_point` on its surface, moves
// with the cursor in the plane through that point facing the camera.
struct ObjectDrag {
    std::size_t collider = 0;
    glm::vec3 plane_point{0.0f};
    glm::vec3 plane_normal{0.0f, 0.0f, 1.0f};
    glm::vec3 start{0.0f};  // the collider's centre (a mesh: its position) when picked
    // Where the cursor puts it: the collider moves there over the frame's time, and is put there when let go
    // (a simulation behind the wall clock, as at a low frame rate, has not yet carried it all the way).
    std::optional<glm::vec3> target;
};

// A recording in progress: every drawn frame written as DIR/frame-NNNNNN.png (one step of integration.dt
// per frame, so the frames play back at 1 / dt frames per second in real time).
struct Recording {
    std::filesystem::path folder;
    long long frames = 0;
    glm::ivec2 size{0};  // the frames' size (framebuffer pixels): a resize ends the recording
};

// "frame-000001.png", the name of a recording's frame `n` (from 1), as ffmpeg's frame-%06d.png reads them.
std::string recording_frame_name(long long n);

// The file dialogs: the desktop's own (zenity, kdialog) when installed, else the ImGui browser.
struct FileDialogs {
    DesktopDialog desktop;
    FileDialogMode desktop_mode = FileDialogMode::Open;
    bool desktop_failed = false;  // the desktop's dialog failed once: the built-in browser for the session
    FileBrowser browser;
    bool open() const { return desktop.running() || browser.is_open(); }
};

struct AppState {
    // The document: name, cloth and pins as edited, what Reset returns to (`loaded`). The live settings are
    // the simulation's alone; document() joins the two into what "Save scene as" writes.
    Scene scene;
    Scene loaded;             // the scene as loaded (after --set) or saved: "reset to scene value" and Revert go here
    std::string scene_source; // bundled name or path it came from
    MassSpring sim;           // the running cloth; owns the live settings (MassSpring::apply)
    Stepper stepper;          // the run policy: fixed step, frame budget, auto substeps, the guard
    RunPolicy start_policy;   // ... as the app started with it: what R restores
    int failures_in_a_row = 0;  // guard failures with no good step between them
    OrbitCamera camera;
    ViewSettings view;
    bool paused = false;
    bool step_once = false;
    // Settle (the panel): while set, each frame runs the dynamics with kinetic damping (settle.hpp) as fast as
    // the frame allows, until the cloth is settled; a new cloth (reset, load, an edit that rebuilds) ends it.
    std::optional<Settler> settling;
    float time_scale = 1.0f;   // simulated seconds per wall second
    bool show_panel = true;
    float panel_width = kPanelWidth;  // window coordinates at content scale 1; the user drags the panel's edge
    bool vsync = true;
    // The window's OpenGL renderer and anti-aliasing, as the View section shows them (window.hpp).
    struct Display {
        std::string renderer;
        int samples = 0;
        bool software = false;
        bool samples_auto_off = false;  // auto chose no multisampling for a software renderer
    } display;
    Stats stats;
    std::optional<Grab> grab;
    std::optional<ObjectDrag> object_drag;
    Messages messages;         // what the app tells the user (errors, notes, screenshot paths)
    FileDialogs dialogs;       // "Open file..." and "Save scene as..."
    RecentFiles recent{std::filesystem::path()};  // the Recent menu (read from the config folder by the app)
    std::filesystem::path settings_file;  // where the app's settings are kept (empty: nowhere, as in scripted runs)
    AppSettings saved_settings{kPanelWidth};  // ... as that file holds them now
    std::optional<Recording> recording;  // Record (F9)
    std::string loaded_toml;   // `loaded` as TOML: the window title marks a document that differs from it

    AppState(const Scene& s, std::string source, const RunPolicy& policy)
        : scene(s), loaded(s), scene_source(std::move(source)), sim(build_simulation(s)), stepper(policy), start_policy(policy) {}

    // The scene as it runs: the document with the simulation's live settings (what Save writes).
    Scene document() const { return running_scene(scene, sim); }

    // Ends a settle, settled or not: the cloth goes on with the scene's own damping.
    void stop_settling() {
        settling.reset();
        sim.set_settle_damping(0.0);
    }
    // A message in the panel's message area; an error, or a warning (`to_stderr`), also goes to stderr.
    void say(std::string message, bool error = false, bool to_stderr = false) {
        if (messages.add(message, error) && (error || to_stderr)) {
            std::cerr << "clothsim: " << message << (message.ends_with('\n') ? "" : "\n");
        }
    }
};

// What the panel asks the app to do after this frame.
struct PanelRequests {
    std::optional<Scene> rebuild;  // cloth or pins changed: rebuild from this edited scene
    bool reset = false;         // back to the start of the document as edited (R)
    bool revert = false;        // back to the scene as loaded or saved, dropping every edit
    bool frame_camera = false;
    bool reset_camera = false;
    bool screenshot = false;
    bool record = false;        // start or stop recording
    bool open_dialog = false;   // "Open file..."
    bool save_dialog = false;   // "Save scene as..."
    bool quit = false;
    std::optional<std::string> load;  // a bundled scene name or a path
    std::optional<std::string> save;  // a path
};

// Draws the settings panel and edits `app` through it (Dear ImGui).
PanelRequests draw_panel(AppState& app, float content_scale);

// Width of the panel in window coordinates (0 when hidden): the 3D view takes the rest of the window.
float panel_width(const AppState& app, float content_scale, float window_width);

}  // namespace clothsim
