// The app's main loop, one straight function as in Dear ImGui's example_glfw_opengl3: poll input, step the
// simulation at a fixed dt, draw the scene, draw the panel, act on what the panel asked.
#include "app.hpp"

#include "clothsim/collider_motion.hpp"

#include "app_state.hpp"
#include "camera.hpp"
#include "frame_log.hpp"
#include "gl.hpp"
#include "layout.hpp"
#include "picking.hpp"
#include "renderer.hpp"
#include "scene_loading.hpp"
#include "shader.hpp"
#include "window.hpp"
#include "exit_codes.hpp"

#include "clothsim/atomic_file.hpp"
#include "clothsim/data_dirs.hpp"
#include "clothsim/scene.hpp"

#include <GLFW/glfw3.h>
#include <glm/common.hpp>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <utility>
#include <vector>

#include <unistd.h>

namespace clothsim {
namespace {

using Clock = std::chrono::steady_clock;

std::filesystem::path texture_directory() {
    return data_directory("CLOTHSIM_TEXTURES", "textures");
}

// The 3D view: the window right of the panel, in window coordinates (x, y from the top-left, w, h).
glm::vec4 view_rect(const AppState& app, const Window& window, float scale) {
    const glm::vec2 size(window.window_size());
    return clothsim::view_rect(size, panel_width(app, scale, size.x));
}

float view_aspect(const AppState& app, const Window& window, float scale) {
    const glm::vec4 r = view_rect(app, window, scale);
    return r.z / r.w;
}

void frame_camera(AppState& app, float aspect) {
    glm::vec3 lo, hi;
    scene_bounds(app.sim, lo, hi);
    app.camera.frame(lo, hi, aspect);
}

void reset_camera(AppState& app, float aspect) {
    glm::vec3 lo, hi;
    scene_bounds(app.sim, lo, hi);
    app.camera = framed_camera(lo, hi, aspect);
}

void record_energy(AppState& app) {
    const Energy e = app.sim.energy();
    app.stats.kinetic.push(static_cast<float>(e.kinetic));
    app.stats.potential.push(static_cast<float>(e.potential()));
    app.stats.total.push(static_cast<float>(e.total()));
}

// What a new cloth resets: the grab, the time owed, the plots, the renderer's buffers.
void after_rebuild(AppState& app, Renderer& renderer) {
    app.stop_settling();
    app.grab.reset();
    app.object_drag.reset();
    app.stepper.restart();
    app.stats.speed = app.time_scale;
    app.stats.window_wall = app.stats.window_simulated = 0.0;
    app.failures_in_a_row = 0;
    app.stats.kinetic.clear();
    app.stats.potential.clear();
    app.stats.total.clear();
    renderer.set_cloth(app.sim);
}

// Builds a new simulation from `scene`, which becomes the document; on a bad scene keeps the old one and
// says why.
bool rebuild(AppState& app, Renderer& renderer, const Scene& scene) {
    try {
        app.sim = build_simulation(scene);
    } catch (const SceneError& e) {
        app.say(std::string("not rebuilt: ") + e.what(), true);
        return false;
    }
    app.scene = scene;
    after_rebuild(app, renderer);
    return true;
}

// What the guard did this frame, told to the user. When it gave up, the grab (the usual cause) is let go
// and the app pauses at the last good state; when it gives up again before any step has succeeded, playing
// on would only fail again, so the scene restarts (returns true: reset).
bool report_guard(AppState& app, const StepReport& report) {
    if (report.steps > 0 && !report.guard_gave_up) app.failures_in_a_row = 0;
    if (report.guard_log.empty()) return false;
    if (!report.guard_gave_up) {
        app.say(report.guard_log, false, true);  // a warning: the step was retried with more substeps
        return false;
    }
    // One message (printed once) with what the guard did and what happens now.
    app.sim.release_grab();
    app.grab.reset();
    if (++app.failures_in_a_row >= 2) {
        app.failures_in_a_row = 0;
        app.say(report.guard_log + "the step failed again from the same state: the scene restarts", true);
        return true;
    }
    app.paused = true;
    app.say(report.guard_log +
                "paused at the last good state; Play tries again from there (a second failure restarts the scene), "
                "R restarts now",
            true);
    return false;
}

// The energy plots gain a point per frame that stepped; a cloth that rested through the frame repeats the
// last values instead of recomputing them.
void record_plots(AppState& app, bool rested) {
    if (rested) {
        app.stats.kinetic.push(app.stats.kinetic.last());
        app.stats.potential.push(app.stats.potential.last());
        app.stats.total.push(app.stats.total.last());
    } else {
        record_energy(app);
    }
}

// Settle's share of a frame: steps with kinetic damping until the cloth settles or kSettleFrameSeconds of wall
// time pass (a settle runs as fast as the machine allows, not in real time; the window stays responsive), and
// in scripted runs and while recording one step a frame. Says how it ended.
constexpr double kSettleFrameSeconds = 0.05;
StepReport settle_frame(AppState& app, bool one_step_a_frame) {
    const auto start = Clock::now();
    StepReport total;
    for (;;) {
        StepReport r = app.stepper.run(app.sim, 1);
        total.steps += r.steps;
        total.guard_log += r.guard_log;
        total.skipped_non_finite = r.skipped_non_finite;
        total.guard_gave_up = r.guard_gave_up;
        if (r.steps == 0 || r.guard_gave_up || r.skipped_non_finite) {
            app.say("settle stopped: the cloth did not step", true);
            app.stop_settling();
            break;
        }
        if (app.settling->after_step(app.sim)) {
            char text[160];
            std::snprintf(text, sizeof text, "settled at t = %.2f s: residual %.3g (tolerance %.3g), %d velocity resets",
                          app.sim.time(), app.settling->residual().value, app.settling->options().tolerance,
                          app.settling->resets());
            app.say(text);
            std::printf("clothsim: %s\n", text);  // and on the terminal, as a finished long job
            std::fflush(stdout);
            app.stop_settling();
            break;
        }
        if (one_step_a_frame || std::chrono::duration<double>(Clock::now() - start).count() >= kSettleFrameSeconds) break;
    }
    app.stepper.restart();  // no real time is owed for what the settle ran
    return total;
}

// This frame's physics, through the stepper: Settle's steps while it runs, one step per frame in scripted runs
// and while recording, one for Step, otherwise
// the wall time that passed (scaled) in fixed steps of integration.dt. Returns true when the scene must
// restart (the guard failed twice in a row).
bool simulate(AppState& app, double wall_seconds, bool one_step_a_frame) {
    const auto start = Clock::now();
    app.sim.reset_profile();
    const bool was_resting = app.sim.asleep();
    StepReport report;
    if (app.settling) {
        report = settle_frame(app, one_step_a_frame);
    } else if (app.step_once) {
        report = app.stepper.run(app.sim, 1);
    } else if (app.paused) {
        report = app.stepper.run(app.sim, 0);  // auto substeps still follows the panel's edits
    } else if (one_step_a_frame) {
        report = app.stepper.run(app.sim, 1);
    } else {
        report = app.stepper.advance(app.sim, wall_seconds * app.time_scale);
    }
    app.step_once = false;
    const bool restart = report_guard(app, report);
    if (report.skipped_non_finite) {
        app.say("the cloth is no longer finite (NaN or infinite positions) and is not stepped; R restarts the scene",
                true);
    }
    if (report.steps > 0) record_plots(app, was_resting && app.sim.asleep());
    if (!app.paused && !one_step_a_frame && !app.settling) {  // playing in real time: is it keeping up?
        app.stats.window_wall += wall_seconds;
        app.stats.window_simulated += double(report.steps) * app.sim.settings().integration.dt;
        if (app.stats.window_wall >= 0.5) {
            app.stats.speed = static_cast<float>(app.stats.window_simulated / app.stats.window_wall);
            app.stats.window_wall = app.stats.window_simulated = 0.0;
        }
    } else {
        app.stats.speed = app.time_scale;
        app.stats.window_wall = app.stats.window_simulated = 0.0;
    }
    app.stats.frame_ms = static_cast<float>(1e3 * wall_seconds);
    app.stats.profile = app.sim.profile();
    app.stats.sim_ms = std::chrono::duration<float, std::milli>(Clock::now() - start).count();
    app.stats.substeps_last_frame = report.steps * app.sim.settings().integration.substeps;
    return restart;
}

// The ray through a point of the window (pixels from its top-left), and through the cursor.
Ray ray_at(const AppState& app, const Window& window, float scale, glm::dvec2 at) {
    const glm::vec4 r = view_rect(app, window, scale);
    return ray_through(app.camera, glm::vec2(at.x - r.x, at.y - r.y), glm::vec2(r.z, r.w));
}
Ray cursor_ray(const AppState& app, const Window& window, float scale) {
    double x = 0.0, y = 0.0;
    glfwGetCursorPos(window.get(), &x, &y);
    return ray_at(app, window, scale, {x, y});
}

// Converts the pins of the running simulation to the scene's explicit list, so "Save scene" keeps them. Soft
// clips hold their particles without pinning them: they stay clips (the preset's as explicit ones).
void pins_to_scene(AppState& app) {
    const int cols = app.sim.topology().cols;  // the running cloth, even if an edit of the grid failed to rebuild
    PinSpec& pins = app.scene.pins;
    std::vector<Pin> soft;
    if (pins.clip == ClipKind::Soft) {
        ClothSettings cloth = app.scene.cloth;
        cloth.rows = app.sim.topology().rows;
        cloth.cols = cols;
        if (pins.preset_radius > 0.0f) {
            for (std::size_t i : pinned_particles(cloth, PinSpec{pins.preset, {}, 0.0f, ClipKind::Rigid})) {
                soft.push_back({static_cast<int>(i) / cols, static_cast<int>(i) % cols, pins.preset_radius});
            }
        }
        for (const Pin& p : pins.particles) {
            if (p.radius > 0.0f) soft.push_back(p);
        }
    }
    app.scene.pins.preset = PinPreset::None;
    app.scene.pins.preset_radius = 0.0f;
    if (soft.empty()) app.scene.pins.clip = ClipKind::Rigid;  // no clip left to hold softly (validate refuses it)
    app.scene.pins.particles = std::move(soft);
    for (std::size_t i = 0; i < app.sim.particle_count(); ++i) {  // every particle a clip holds, one by one
        if (app.sim.state().pinned[i] != kPinned) continue;
        if (app.sim.topology().mesh) {  // a mesh cloth's pins name vertices
            app.scene.pins.particles.push_back({0, 0, 0.0f, static_cast<int>(i)});
        } else {
            app.scene.pins.particles.push_back({static_cast<int>(i) / cols, static_cast<int>(i) % cols});
        }
    }
}

// Left-drag on the cloth grabs a particle: a free one is pulled by the simulation's force-limited grab
// spring (MassSpring::grab), a pinned one is moved (the pin goes where the mouse takes it).
void drag_grabbed(AppState& app, const Window& window, float scale) {
    const Grab& grab = *app.grab;
    const auto p = intersect_plane(cursor_ray(app, window, scale), grab.plane_point, grab.plane_normal);
    if (!p) return;
    if (grab.was_pinned) app.sim.drag_pin(grab.particle, *p);
    else app.sim.grab(grab.particle, *p);
}

// Whether segments ab and cd cross on screen (strictly: touching at an end does not count).
bool segments_cross(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 d) {
    auto side = [](glm::vec2 p, glm::vec2 q, glm::vec2 r) {
        const float v = (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
        return (v > 0.0f) - (v < 0.0f);
    };
    return side(a, b, c) * side(a, b, d) < 0 && side(c, d, a) * side(c, d, b) < 0;
}

// Shift + right-drag cuts: the springs whose ends, as drawn, lie on either side of the stroke's last piece
// (the cursor's move since the last frame) break, as Blender's knife cuts what the stroke crosses.
void cut_along_stroke(AppState& app, const Window& window, float scale, glm::vec2 from, glm::vec2 to) {
    if (from == to) return;
    const glm::vec4 r = view_rect(app, window, scale);
    const glm::vec2 origin(r.x, r.y), viewport(r.z, r.w);
    const glm::vec2 a = from - origin, b = to - origin;
    const std::size_t broken = app.sim.cut([&](glm::vec3 p, glm::vec3 q) {
        const glm::vec3 sp = project(app.camera, p, viewport), sq = project(app.camera, q, viewport);
        const bool visible = sp.z > 0.0f && sp.z < 1.0f && sq.z > 0.0f && sq.z < 1.0f;
        return visible && segments_cross(a, b, glm::vec2(sp), glm::vec2(sq));
    });
    if (broken > 0) app.say("cut " + std::to_string(broken) + " springs");
}

// The object under the cursor (alt + click): the nearest enabled collider the cursor's ray enters, and where.
std::optional<ObjectDrag> pick_object(const AppState& app, const Ray& ray) {
    const glm::dvec3 from(ray.origin), to = from + glm::dvec3(ray.direction) * kShapeReach;
    std::optional<ObjectDrag> best;
    double nearest = INFINITY;
    const std::vector<Collider>& list = app.sim.colliders();
    for (std::size_t i = 0; i < list.size(); ++i) {
        if (!list[i].enabled) continue;
        const auto t = segment_entry(list[i], from, to);
        if (!t || *t >= nearest) continue;
        nearest = *t;
        best = ObjectDrag{i, glm::vec3(from + *t * (to - from)), -app.camera.forward(), glm::vec3(pivot(list[i])), {}};
    }
    return best;
}

// Alt + left-drag moves an object in the plane facing the camera: the simulation moves it toward the cursor
// over the time this frame will simulate (MassSpring::move_collider), so the cloth it touches is pushed and
// carried with that velocity; released, it stays where it got to. While paused it is put there at once.
void drag_object(AppState& app, const Window& window, float scale) {
    ObjectDrag& drag = *app.object_drag;
    const auto p = intersect_plane(cursor_ray(app, window, scale), drag.plane_point, drag.plane_normal);
    if (!p) return;
    const double dt = app.sim.settings().integration.dt;
    const double seconds = app.paused ? 0.0 : std::max(dt, 1e-3 * app.stats.frame_ms * app.time_scale);
    drag.target = drag.start + (*p - drag.plane_point);
    app.sim.move_collider(drag.collider, *drag.target, seconds);
}

// Let go: the collider is put where the cursor last put it, at rest.
void release_object(AppState& app) {
    const std::size_t i = app.object_drag->collider;
    const std::optional<glm::vec3> target = app.object_drag->target;
    app.object_drag.reset();
    const std::vector<Collider>& list = app.sim.colliders();
    if (i >= list.size()) return;
    const glm::vec3 at = target ? *target : glm::vec3(pivot(list[i]));
    app.sim.move_collider(i, at, 0.0);
    char line[160];
    std::snprintf(line, sizeof line, "collider %zu (%s) moved to (%.3g, %.3g, %.3g)", i,
                  std::string(kind_name(list[i])).c_str(), at.x, at.y, at.z);
    app.say(line);
}

void handle_mouse(AppState& app, const Window& window, float scale) {
    const ImGuiIO& io = ImGui::GetIO();
    const glm::vec2 delta(io.MouseDelta.x, io.MouseDelta.y);
    const float height = static_cast<float>(window.window_size().y);
    if (app.object_drag) {
        if (ImGui::IsMouseDown(ImGuiMouseButton_Left)) drag_object(app, window, scale);
        else release_object(app);
        return;
    }
    if (app.grab) {
        if (ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
            drag_grabbed(app, window, scale);
        } else {
            app.sim.release_grab();
            app.grab.reset();
        }
        return;
    }
    if (io.WantCaptureMouse) return;
    if (io.KeyShift && ImGui::IsMouseDown(ImGuiMouseButton_Right)) {
        const glm::vec2 to(io.MousePos.x, io.MousePos.y);
        cut_along_stroke(app, window, scale, to - delta, to);
        return;
    }
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left) && io.KeyAlt) {
        app.object_drag = pick_object(app, cursor_ray(app, window, scale));
        if (!app.object_drag) app.say("alt + drag moves an object: there is none under the cursor");
        return;
    }
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift) {
        std::vector<glm::vec3> positions = app.sim.positions();
        // Slots outside the cloth's shape are not there to pick.
        for (std::size_t i = 0; i < positions.size(); ++i) {
            if (app.sim.state().pinned[i] == kAbsent) positions[i] = glm::vec3(NAN);
        }
        const auto hit = pick_particle(cursor_ray(app, window, scale), positions, pick_spread(app.camera, 10.0f, height));
        if (hit && io.KeyCtrl) {
            const bool pinned = !app.sim.particle(*hit).pinned;
            app.sim.set_pinned(*hit, pinned);
            pins_to_scene(app);
            app.say("particle " + std::to_string(*hit) + (pinned ? " pinned" : " unpinned"));
        } else if (hit) {
            app.grab = Grab{*hit, app.sim.particle(*hit).pinned, positions[*hit], -app.camera.forward()};
            drag_grabbed(app, window, scale);
        }
    }
    if (app.grab) return;
    const bool left_drag = ImGui::IsMouseDragging(ImGuiMouseButton_Left, 0.0f);
    if ((left_drag && io.KeyShift) || ImGui::IsMouseDragging(ImGuiMouseButton_Right, 0.0f) ||
        ImGui::IsMouseDragging(ImGuiMouseButton_Middle, 0.0f)) {
        app.camera.pan(delta, height);
    } else if (left_drag) {
        app.camera.orbit(delta);
    }
    if (io.MouseWheel != 0.0f) app.camera.zoom(io.MouseWheel);
    // A floor that collides is solid: the camera never goes under the lowest.
    float floor = INFINITY;
    for (const Collider& c : app.sim.colliders()) {
        if (const auto* plane = std::get_if<PlaneCollider>(&c.shape); plane && c.enabled) floor = std::min(floor, plane->height);
    }
    if (std::isfinite(floor)) app.camera.keep_above(floor);
}

// Key presses and dropped files collected by GLFW callbacks, in front of Dear ImGui's own. ImGui 1.86 (before
// its 1.87 input queue) reads each key's state once a frame, in NewFrame, so a key pressed and released
// between two frames (a quick tap at a low frame rate) never reaches it: Enter would not end a typed value.
// The queue hands ImGui the press at once and holds back a release of a key pressed since the last frame
// until that frame has seen the key down, so every tap counts once. For the same reason it holds back every
// key release that follows a mouse press between two frames: ImGui sees the click with the modifiers held
// when it was made (a quick ctrl+click at 5 frames a second would otherwise reach it as a plain click, and a
// plain click on a slider sets it to the value under the mouse).
struct InputQueue {
    std::vector<int> pressed;          // this frame's presses, for the app's own keys
    std::vector<std::string> dropped;  // paths dropped onto the window since the last frame
    GLFWkeyfun imgui_key = nullptr;    // ImGui's key callback, which this queue feeds
    GLFWmousebuttonfun imgui_mouse_button = nullptr;  // ... and its mouse button callback
    GLFWcursorposfun imgui_cursor = nullptr;          // ... and its cursor callback
    // Where the cursor was last reported, a drag-and-drop's position included (GLFW reports XdndPosition as
    // a cursor move; glfwGetCursorPos asks the X server for the pointer, which a drop does not move), and
    // where it was when files were dropped.
    glm::dvec2 cursor{NAN, NAN};
    glm::dvec2 dropped_at{NAN, NAN};
    struct Release {
        int key, scancode, mods;
    };
    std::vector<int> down_this_frame;   // keys pressed since the last frame
    bool clicked_this_frame = false;    // a mouse button pressed since the last frame
    std::vector<Release> held_releases; // releases handed to ImGui after the frame
};

void on_key(GLFWwindow* window, int key, int scancode, int action, int mods) {
    auto* queue = static_cast<InputQueue*>(glfwGetWindowUserPointer(window));
    if (!queue) return;
    if (action == GLFW_PRESS) {
        queue->pressed.push_back(key);
        queue->down_this_frame.push_back(key);
    }
    if (action == GLFW_RELEASE &&
        (queue->clicked_this_frame ||
         std::find(queue->down_this_frame.begin(), queue->down_this_frame.end(), key) != queue->down_this_frame.end())) {
        queue->held_releases.push_back({key, scancode, mods});
        return;
    }
    if (queue->imgui_key) queue->imgui_key(window, key, scancode, action, mods);
}

void on_mouse_button(GLFWwindow* window, int button, int action, int mods) {
    auto* queue = static_cast<InputQueue*>(glfwGetWindowUserPointer(window));
    if (!queue) return;
    if (action == GLFW_PRESS) queue->clicked_this_frame = true;
    if (queue->imgui_mouse_button) queue->imgui_mouse_button(window, button, action, mods);
}

// Before the next events are read: the releases held back reach ImGui, which saw their keys down last frame.
void release_held_keys(GLFWwindow* window, InputQueue& queue) {
    queue.down_this_frame.clear();
    queue.clicked_this_frame = false;
    for (const InputQueue::Release& r : std::exchange(queue.held_releases, {})) {
        if (queue.imgui_key) queue.imgui_key(window, r.key, r.scancode, GLFW_RELEASE, r.mods);
    }
}

void on_drop(GLFWwindow* window, int count, const char** paths) {
    auto* queue = static_cast<InputQueue*>(glfwGetWindowUserPointer(window));
    if (!queue) return;
    for (int i = 0; i < count; ++i) queue->dropped.emplace_back(paths[i]);
    queue->dropped_at = queue->cursor;
}

void on_cursor(GLFWwindow* window, double x, double y) {
    auto* queue = static_cast<InputQueue*>(glfwGetWindowUserPointer(window));
    if (!queue) return;
    queue->cursor = {x, y};
    if (queue->imgui_cursor) queue->imgui_cursor(window, x, y);
}

// Files dropped onto the window: the first .toml opens as "Open file" would; .obj files are added as mesh
// colliders under the cursor; the others are refused, said why.
void handle_drop(AppState& app, const Window& window, float scale, InputQueue& input, PanelRequests& requests) {
    if (input.dropped.empty()) return;
    if (app.dialogs.open()) {  // the dialog's answer would land on top of the dropped scene
        app.say("dropped files not opened: a file dialog is open; close it first", true);
        input.dropped.clear();
        return;
    }
    const DropChoice choice = choose_dropped_scene(input.dropped);
    input.dropped.clear();
    for (const std::string& why : choice.refused) app.say(why, true);
    if (choice.open) {
        requests.load = choice.open;  // a new scene: the meshes dropped with it would land in the old one
        for (const std::string& mesh : choice.meshes) app.say("dropped " + mesh + ": not added: a scene was dropped with it", true);
        return;
    }
    // Meshes land under the cursor on the floor (the first plane that collides, else y = 0), or 2 m in front
    // of the camera when the cursor is above the horizon.
    float floor = 0.0f;
    for (const Collider& c : app.sim.colliders()) {
        if (const auto* plane = std::get_if<PlaneCollider>(&c.shape); plane && c.enabled) {
            floor = plane->height;
            break;
        }
    }
    const Ray ray = std::isfinite(input.dropped_at.x) ? ray_at(app, window, scale, input.dropped_at) : cursor_ray(app, window, scale);
    const auto on_floor = intersect_plane(ray, glm::vec3(0.0f, floor, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f));
    const glm::vec3 at = on_floor && glm::distance(*on_floor, ray.origin) < 100.0f ? *on_floor : ray.origin + 2.0f * ray.direction;
    for (const std::string& mesh : choice.meshes) {
        const std::string said = add_dropped_mesh(mesh, at, app.sim);
        app.say(said, !said.starts_with("added"));
    }
}

void handle_keys(AppState& app, InputQueue& input, PanelRequests& requests) {
    const std::vector<int> pressed_keys = std::move(input.pressed);
    input.pressed.clear();
    auto pressed = [&](int key) {
        return std::find(pressed_keys.begin(), pressed_keys.end(), key) != pressed_keys.end();
    };
    // F12 types nothing: it takes a screenshot even while a text field has the keyboard.
    if (pressed(GLFW_KEY_F12)) requests.screenshot = true;
    if (pressed(GLFW_KEY_F9)) requests.record = true;
    // While a file dialog is open the keys are its own (Escape closes it, never the app behind it).
    if (ImGui::GetIO().WantCaptureKeyboard || app.dialogs.open()) return;
    if (pressed(GLFW_KEY_SPACE)) app.paused = !app.paused;
    if (pressed(GLFW_KEY_S)) {
        app.paused = true;
        app.step_once = true;
    }
    if (pressed(GLFW_KEY_R)) requests.reset = true;
    if (pressed(GLFW_KEY_W)) app.view.wireframe = !app.view.wireframe;
    if (pressed(GLFW_KEY_H)) app.show_panel = !app.show_panel;
    if (pressed(GLFW_KEY_F)) requests.frame_camera = true;
    if (pressed(GLFW_KEY_HOME)) requests.reset_camera = true;
    if (pressed(GLFW_KEY_ESCAPE)) requests.quit = true;
}

// Where the file dialogs start: the folder of the scene's file, else of the most recent file, else the
// working folder.
std::filesystem::path dialog_folder(const AppState& app) {
    std::error_code ec;
    if (is_scene_file(app.scene_source)) return std::filesystem::absolute(app.scene_source, ec).parent_path();
    if (!app.recent.files().empty()) return std::filesystem::path(app.recent.files().front()).parent_path();
    return std::filesystem::current_path(ec);
}

// "Open file..." and "Save scene as...": the desktop's dialog (zenity, kdialog) when there is one, else the
// ImGui browser. Saving proposes the scene's own file, or NAME-edited.toml in the working folder.
void start_file_dialog(AppState& app, FileDialogMode mode) {
    if (app.dialogs.open()) return;
    const bool from_file = is_scene_file(app.scene_source);
    std::error_code ec;
    const std::filesystem::path folder =
        mode == FileDialogMode::Save && !from_file ? std::filesystem::current_path(ec) : dialog_folder(app);
    const std::string name = mode == FileDialogMode::Open ? ""
                             : from_file                  ? std::filesystem::path(app.scene_source).filename().string()
                                                          : app.scene.name + "-edited.toml";
    const auto tool = app.dialogs.desktop_failed ? std::nullopt : desktop_dialog_tool();
    if (tool) {
        const std::string error = app.dialogs.desktop.start(dialog_command(*tool, mode, folder, name));
        if (error.empty()) {
            app.dialogs.desktop_mode = mode;
            return;
        }
        app.dialogs.desktop_failed = true;
        app.say(error + "; using the built-in file browser from now on", true);
    }
    app.dialogs.browser.open(mode, folder, name);
}

// A chosen file becomes a load or a save request.
void ask_for(PanelRequests& requests, FileDialogMode mode, const std::string& path) {
    if (mode == FileDialogMode::Open) requests.load = path;
    else requests.save = path;
}

// The desktop dialog's file to save: a name typed without .toml gets it, as the built-in browser does, but
// a file of that new name the dialog never asked about is not replaced. Nothing (and a message) then.
std::optional<std::string> save_name(AppState& app, const std::string& chosen) {
    if (std::filesystem::path(chosen).extension() == ".toml") return chosen;
    const std::string path = chosen + ".toml";
    std::error_code ec;
    if (std::filesystem::exists(path, ec)) {
        app.say("not saved: " + path + " exists; choose it in the dialog to replace it", true);
        return std::nullopt;
    }
    return path;
}

// The desktop dialog, polled once a frame: its choice, or why it failed (then the built-in browser opens).
void poll_file_dialog(AppState& app, PanelRequests& requests) {
    if (!app.dialogs.desktop.running()) return;
    const auto result = app.dialogs.desktop.poll();
    if (!result) return;
    if (result->path && app.dialogs.desktop_mode == FileDialogMode::Save) {
        if (const auto path = save_name(app, *result->path)) ask_for(requests, FileDialogMode::Save, *path);
    } else if (result->path) {
        ask_for(requests, FileDialogMode::Open, *result->path);
    }
    if (!result->error.empty()) {  // not tried again this session: the same tool would fail the same way
        app.dialogs.desktop_failed = true;
        app.say(result->error + "; using the built-in file browser from now on", true);
        start_file_dialog(app, app.dialogs.desktop_mode);
    }
}

// The loaded scene becomes what the title compares against, and a file joins the recent files.
void loaded_from(AppState& app, const std::string& source) {
    app.scene_source = source;
    app.loaded_toml = to_toml(app.loaded);
    if (is_scene_file(source)) {
        if (const std::string error = app.recent.add(source); !error.empty()) app.say("recent files not saved: " + error, true);
    }
}

// Atomic (atomic_file.hpp): a failed save leaves the old file as it was and says why. A saved scene is the
// document's file from then on, as in any editor: the title loses its mark, and R returns to what was saved.
bool save_scene(AppState& app, const std::string& path) {
    std::string error;
    const Scene document = app.document();
    if (!write_file_atomically(path, to_toml(document), error)) {
        app.say("not saved: " + error, true);
        return false;
    }
    app.loaded = document;
    loaded_from(app, path);
    app.say("saved " + path);
    return true;
}

// The window title names the scene, with a '*' when the settings differ from the file it came from (or
// from the bundled scene). Auto substeps and the guard choose integration.substeps themselves: that is no
// edit of the user's.
void update_title(AppState& app, const Window& window, std::string& shown) {
    Scene document = app.document();
    document.settings.integration.substeps = app.loaded.settings.integration.substeps;
    const std::string title = "clothsim - " + app.scene.name + (to_toml(document) != app.loaded_toml ? "*" : "");
    if (title == shown) return;
    glfwSetWindowTitle(window.get(), title.c_str());
    shown = title;
}

void apply_requests(AppState& app, Renderer& renderer, const Window& window, float scale, PanelRequests& requests) {
    const float aspect = view_aspect(app, window, scale);
    if (requests.open_dialog) start_file_dialog(app, FileDialogMode::Open);
    if (requests.save_dialog) start_file_dialog(app, FileDialogMode::Save);
    if (requests.load) {
        // Loaded and built in one step: a rejected file keeps the user's edits and the running cloth.
        if (auto error = open_scene(*requests.load, app.scene, app.loaded, app.sim)) {
            app.say(*error, true);
        } else {
            loaded_from(app, *requests.load);
            after_rebuild(app, renderer);
            reset_camera(app, aspect);
            app.say("loaded " + *requests.load);
            for (const std::string& note : app.loaded.notes) app.say(note);
        }
    }
    if (requests.reset || requests.revert) {
        // R returns to the start of the document as edited (its pins, grid and settings), with the substeps
        // the scene asked for: those auto substeps or the guard chose are no edit. Revert returns to the file.
        Scene start = requests.revert ? app.loaded : app.document();
        start.settings.integration.substeps = app.loaded.settings.integration.substeps;
        if (rebuild(app, renderer, start)) {
            app.stepper = Stepper(app.start_policy);  // auto substeps back on if the guard turned it off
            app.say(requests.revert ? "reverted to " + app.scene_source + ", as saved"
                                    : "reset to the start of " + app.scene.name + " as edited");
        }
    }
    if (requests.rebuild) rebuild(app, renderer, *requests.rebuild);
    if (requests.save) save_scene(app, *requests.save);
    if (requests.frame_camera) frame_camera(app, aspect);
    if (requests.reset_camera) reset_camera(app, aspect);
}

}  // namespace

bool apply_view_option(ViewSettings& view, bool& show_panel, const std::string& item) {
    if (item == "wireframe") view.wireframe = true;
    else if (item == "springs=kind") view.springs = SpringView::ByKind;
    else if (item == "springs=strain") view.springs = SpringView::ByStrain;
    else if (item == "particles") view.particles = true;
    else if (item == "no-pins") view.highlight_pins = false;
    else if (item == "no-texture") view.texture = false;
    else if (item == "no-shadows") view.shadows = false;
    else if (item == "no-panel") show_panel = false;
    else return false;
    return true;
}

std::string timestamped_screenshot_name() {
    const std::time_t now = std::time(nullptr);
    char stamp[64];
    std::strftime(stamp, sizeof stamp, "clothsim-%Y%m%d-%H%M%S", std::localtime(&now));
    // Two screenshots within a second get -2, -3, ...: a name never overwrites an earlier file.
    std::string name = std::string(stamp) + ".png";
    for (int n = 2; std::filesystem::exists(name); ++n) name = std::string(stamp) + "-" + std::to_string(n) + ".png";
    return name;
}

std::string write_screenshot(const std::string& path, int width, int height) {
    std::vector<unsigned char> pixels(static_cast<std::size_t>(width) * height * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
    // Opaque: the panel's translucency must not make the PNG see-through.
    for (std::size_t i = 3; i < pixels.size(); i += 4) pixels[i] = 255;
    stbi_flip_vertically_on_write(1);
    if (!stbi_write_png(path.c_str(), width, height, 4, pixels.data(), width * 4)) {
        return "cannot write screenshot '" + path + "'";
    }
    return "";
}

namespace {

// Dear ImGui over GLFW and OpenGL 3.3, scaled for the monitor; no ini file (the panel's layout is fixed; its
// width is one of the app's settings, app_settings.hpp).
void start_imgui(const Window& window, InputQueue& input, float scale) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;
    ImFontConfig font;
    font.SizePixels = 13.0f * scale;
    io.Fonts->AddFontDefault(&font);
    ImGui::StyleColorsDark();
    ImGui::GetStyle().ScaleAllSizes(scale);
    glfwSetWindowUserPointer(window.get(), &input);
    glfwSetDropCallback(window.get(), on_drop);
    ImGui_ImplGlfw_InitForOpenGL(window.get(), true);
    // In front of ImGui's key and mouse button callbacks, which the queue then feeds (InputQueue).
    input.imgui_key = glfwSetKeyCallback(window.get(), on_key);
    input.imgui_mouse_button = glfwSetMouseButtonCallback(window.get(), on_mouse_button);
    input.imgui_cursor = glfwSetCursorPosCallback(window.get(), on_cursor);
    ImGui_ImplOpenGL3_Init("#version 330 core");
}

void stop_imgui() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
}

// The panel's start values: the view options, and the file fields filled with the scene's path and an
// "-edited" name to save to.
void start_panel(AppState& app, const AppOptions& options) {
    app.paused = options.start_paused;
    app.view = options.view;
    app.show_panel = options.show_panel;
}

// The 3D view's viewport in framebuffer pixels (x, y from the bottom-left, width, height).
glm::ivec4 view_viewport(const AppState& app, const Window& window, float scale, glm::ivec2 framebuffer) {
    const glm::vec4 rect = view_rect(app, window, scale);
    const float to_pixels = float(framebuffer.x) / float(std::max(window.window_size().x, 1));
    return {glm::round(rect.x * to_pixels), 0, glm::round(rect.z * to_pixels), framebuffer.y};
}

// The app's settings are written when one has changed and no drag is under way (a drag of the panel's edge is
// saved once, when the button is released).
void save_settings_when_changed(AppState& app) {
    const AppSettings now{app.panel_width};
    if (app.settings_file.empty() || now == app.saved_settings || ImGui::IsMouseDown(ImGuiMouseButton_Left)) return;
    if (const std::string error = write_app_settings(app.settings_file, now); !error.empty()) {
        app.say("settings not saved: " + error, true);
        app.settings_file.clear();  // told once; the run goes on with the settings in memory
        return;
    }
    app.saved_settings = now;
}

// Draws the scene and the panel; returns what the panel asked for.
PanelRequests draw_frame(AppState& app, Renderer& renderer, const Window& window, float scale) {
    const auto render_start = Clock::now();
    const glm::ivec2 fb = window.framebuffer_size();
    std::optional<std::size_t> grabbed;
    if (app.grab) grabbed = app.grab->particle;
    renderer.draw({app.sim, app.camera, fb, view_viewport(app, window, scale, fb), app.view, grabbed});
    const Renderer::ClothTimings& cloth = renderer.cloth_timings();
    app.stats.cloth_uploaded = cloth.cloth_uploaded;
    app.stats.times.add_frame(app.stats.profile, cloth.normals_ms, cloth.upload_ms);
    PanelRequests requests;
    if (app.show_panel) requests = draw_panel(app, scale);
    save_settings_when_changed(app);
    if (auto chosen = app.dialogs.browser.draw(scale)) ask_for(requests, app.dialogs.browser.mode(), *chosen);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    app.stats.render_ms = std::chrono::duration<float, std::milli>(Clock::now() - render_start).count();
    return requests;
}

// The panel's requests join the keys' (a key and a button may ask for the same thing).
void merge_requests(PanelRequests& into, const PanelRequests& panel) {
    if (panel.rebuild) into.rebuild = panel.rebuild;
    into.reset |= panel.reset;
    into.revert |= panel.revert;
    into.frame_camera |= panel.frame_camera;
    into.reset_camera |= panel.reset_camera;
    into.screenshot |= panel.screenshot;
    into.record ^= panel.record;  // F9 and the button in one frame cancel out
    into.open_dialog |= panel.open_dialog;
    into.save_dialog |= panel.save_dialog;
    into.quit |= panel.quit;
    if (panel.load) into.load = panel.load;
    if (panel.save) into.save = panel.save;
}

// A new folder for F9's recording in the working folder: clothsim-recording-YYYYMMDD-HHMMSS (-2, -3, ...
// when taken), or the error.
std::filesystem::path new_recording_folder(std::string& error) {
    const std::time_t now = std::time(nullptr);
    char stamp[64];
    std::strftime(stamp, sizeof stamp, "clothsim-recording-%Y%m%d-%H%M%S", std::localtime(&now));
    std::string name = stamp;
    std::error_code ec;
    for (int n = 2; std::filesystem::exists(name, ec); ++n) name = std::string(stamp) + "-" + std::to_string(n);
    if (!std::filesystem::create_directory(name, ec)) error = "cannot create the folder " + name + ": " + ec.message();
    return std::filesystem::absolute(name, ec);
}

// `text` as one shell word: as it is when it holds only safe characters, else in single quotes.
std::string shell_word(const std::string& text) {
    if (text.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789/._-%+=:,") == std::string::npos) {
        return text;
    }
    std::string quoted = "'";
    for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

// The one-line ffmpeg command that makes a video of a recording, at its frame rate (1 / dt: one step a frame).
std::string video_command(const AppState& app, const std::filesystem::path& folder) {
    char rate[32];
    std::snprintf(rate, sizeof rate, "%g", 1.0 / app.sim.settings().integration.dt);
    return std::string("ffmpeg -framerate ") + rate + " -i " + shell_word((folder / "frame-%06d.png").string()) +
           " -pix_fmt yuv420p " + shell_word(folder.string() + ".mp4");
}

// F9 and the Record button: start recording into a new folder, or stop and say how to make the video.
void toggle_recording(AppState& app) {
    if (app.recording) {
        app.say("recorded " + std::to_string(app.recording->frames) + " frames to " + app.recording->folder.string() +
                "; make a video: " + video_command(app, app.recording->folder));
        app.recording.reset();
        return;
    }
    std::string error;
    const std::filesystem::path folder = new_recording_folder(error);
    if (!error.empty()) {
        app.say("not recording: " + error, true);
        return;
    }
    app.recording = Recording{folder, 0, {}};
    app.say("recording every frame to " + folder.string() + " (one step of integration.dt per frame); F9 stops");
}

// While recording, this frame (the back buffer, panel included) as the next numbered PNG. A frame that cannot
// be written stops the recording and says why.
bool record_frame(AppState& app, glm::ivec2 fb) {
    if (!app.recording) return true;
    if (app.recording->frames > 0 && fb != app.recording->size) {
        app.say("recording stopped after " + std::to_string(app.recording->frames) +
                    " frames: the window changed size (a video's frames share one size); F9 starts a new one",
                true);
        app.recording.reset();
        return true;
    }
    app.recording->size = fb;
    const std::filesystem::path file = app.recording->folder / recording_frame_name(app.recording->frames + 1);
    const int level = std::exchange(stbi_write_png_compression_level, 5);
    const int filter = std::exchange(stbi_write_force_png_filter, 1);
    const std::string error = write_screenshot(file.string(), fb.x, fb.y);
    stbi_write_png_compression_level = level;
    stbi_write_force_png_filter = filter;
    if (!error.empty()) {
        app.say(error + "; recording stopped after " + std::to_string(app.recording->frames) + " frames", true);
        app.recording.reset();
        return false;
    }
    ++app.recording->frames;
    return true;
}

// A scripted run's last frame: the screenshot it asked for. Returns the exit code.
int finish_scripted(const AppState& app, const AppOptions& options, glm::ivec2 fb, long long frame) {
    if (app.recording) {
        std::cout << "wrote " << app.recording->frames << " frames to " << app.recording->folder.string() << " ("
                  << fb.x << "x" << fb.y << "); make a video: " << video_command(app, app.recording->folder) << "\n";
    }
    if (options.screenshot.empty()) return kExitOk;
    const std::string error = write_screenshot(options.screenshot, fb.x, fb.y);
    if (!error.empty()) {
        std::cerr << "clothsim: error: " << error << "\n";
        return kExitBadInput;
    }
    std::cout << "wrote " << options.screenshot << " (" << fb.x << "x" << fb.y << ", frame " << frame << ")\n";
    return kExitOk;
}

// F12: a timestamped PNG in the working directory, and where it went.
void take_screenshot(AppState& app, glm::ivec2 fb) {
    const std::string path = timestamped_screenshot_name();
    const std::string error = write_screenshot(path, fb.x, fb.y);
    app.say(error.empty() ? "screenshot saved to " + std::filesystem::absolute(path).string() : error, !error.empty());
}

// The window, the renderer and ImGui around one AppState, and the frame loop: input, physics, drawing, then
// what the frame asked for. Returns the exit code.
int main_loop(Window& window, Renderer& renderer, AppState& app, const AppOptions& options, float scale) {
    const bool scripted = options.frames.has_value();
    std::optional<FrameLog> frame_log;  // --frame-times
    if (!options.frame_times.empty()) {
        try {
            frame_log.emplace(options.frame_times);
        } catch (const std::exception& e) {
            std::cerr << "clothsim: error: --frame-times: " << e.what() << "\n";
            return kExitBadInput;
        }
    }
    InputQueue input;
    start_imgui(window, input, scale);
    std::string title;
    int exit_code = kExitOk;
    long long frame = 0;
    bool vsync_applied = !scripted;
    auto last = Clock::now();
    const auto started = last;
    while (!glfwWindowShouldClose(window.get())) {
        release_held_keys(window.get(), input);
        glfwPollEvents();
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();

        PanelRequests requests;
        handle_keys(app, input, requests);
        handle_drop(app, window, scale, input, requests);
        poll_file_dialog(app, requests);
        handle_mouse(app, window, scale);
        const auto now = Clock::now();
        requests.reset |= simulate(app, std::chrono::duration<double>(now - last).count(), scripted || app.recording);
        last = now;
        merge_requests(requests, draw_frame(app, renderer, window, scale));
        ++frame;
        if (frame_log && !frame_log->write({app.stats.frame_ms, app.stats.sim_ms, app.stats.render_ms,
                                            app.stats.substeps_last_frame}, app.sim)) {
            std::cerr << "clothsim: error: --frame-times: cannot write " << options.frame_times << "\n";
            frame_log.reset();
            exit_code = kExitBadInput;
        }

        // A GL error is a bug in the renderer: scripted runs (the tests) fail on it; interactive ones say so.
        if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
            char text[96];
            std::snprintf(text, sizeof text, "OpenGL error 0x%04X in frame %lld", error, frame);
            if (scripted) {
                std::cerr << "clothsim: error: " << text << "\n";
                exit_code = kExitGlError;
                break;
            }
            app.say(text, true);
        }
        const glm::ivec2 fb = window.framebuffer_size();
        if (!record_frame(app, fb) && scripted) {
            exit_code = kExitBadInput;
            break;
        }
        if (scripted && frame >= *options.frames) {
            exit_code = finish_scripted(app, options, fb, frame);
            break;
        }
        if (requests.screenshot) take_screenshot(app, fb);
        if (requests.record) toggle_recording(app);
        if (!scripted && app.vsync != vsync_applied) {
            window.set_vsync(app.vsync);
            vsync_applied = app.vsync;
        }
        glfwSwapBuffers(window.get());
        if (options.quit_after && std::chrono::duration<double>(Clock::now() - started).count() >= *options.quit_after) {
            requests.quit = true;
        }
        if (requests.quit) glfwSetWindowShouldClose(window.get(), GLFW_TRUE);
        apply_requests(app, renderer, window, scale, requests);
        update_title(app, window, title);
    }
    if (app.recording && !scripted) {  // closing the window ends a recording: say where it is, on stdout too
        const std::string folder = app.recording->folder.string();
        std::cout << "recorded " << app.recording->frames << " frames to " << folder
                  << "; make a video: " << video_command(app, app.recording->folder) << "\n";
        app.recording.reset();
    }
    stop_imgui();
    return exit_code;
}

}  // namespace

std::string recording_frame_name(long long n) {
    char name[32];
    std::snprintf(name, sizeof name, "frame-%06lld.png", n);
    return name;
}

std::string prepare_record_folder(const std::filesystem::path& folder) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec || !std::filesystem::is_directory(folder, ec)) {
        return "cannot create the folder" + (ec ? ": " + ec.message() : std::string(": a file has that name"));
    }
    if (::access(folder.c_str(), W_OK) != 0) return std::string("cannot write frames into the folder: ") + std::strerror(errno);
    if (std::filesystem::exists(folder / recording_frame_name(1), ec)) {
        return "the folder already holds a recording (" + recording_frame_name(1) +
               "); its frames would mix with the new ones: choose a new or empty folder";
    }
    return "";
}

int run_app(const Scene& scene, const AppOptions& options) {
    const bool scripted = options.frames.has_value();
    std::optional<Window> window;
    try {
        window.emplace(options.size, "clothsim - " + scene.name, !scripted, options.samples);
    } catch (const WindowError& e) {
        std::cerr << "clothsim: error: " << e.what() << "\n";
        return kExitBadInput;
    }
    if (scripted && !options.screenshot.empty()) {
        const auto parent = std::filesystem::path(options.screenshot).parent_path();
        if (!parent.empty() && !std::filesystem::is_directory(parent)) {
            std::cerr << "clothsim: error: --screenshot " << options.screenshot << ": the directory does not exist\n";
            return kExitBadInput;
        }
    }
    if (!options.record.empty()) {
        if (const std::string error = prepare_record_folder(options.record); !error.empty()) {
            std::cerr << "clothsim: error: --record " << options.record << ": " << error << "\n";
            return kExitBadInput;
        }
    }
    std::optional<Renderer> renderer;
    try {
        renderer.emplace(gl::shader_directory(), texture_directory());
    } catch (const std::exception& e) {
        std::cerr << "clothsim: error: " << e.what() << "\n";
        return kExitBadInput;
    }

    // The app steps with the guard on: a blow-up is rolled back, retried, and told, never drawn.
    RunPolicy policy;
    policy.auto_substeps = options.auto_substeps;
    policy.safety = options.safety;
    policy.guard = true;
    AppState app(scene, options.scene_source, policy);
    app.display = {window->renderer(), window->samples(), window->software(), window->samples_chosen_for_software()};
    if (app.display.samples_auto_off) {
        std::cout << "clothsim: anti-aliasing off on the software renderer " << app.display.renderer
                  << " (--samples 4 turns it on)\n";
    }
    start_panel(app, options);
    if (!scripted) {  // scripted runs leave the user's recent files and settings alone
        app.recent = RecentFiles::from_config();
        app.settings_file = app_settings_file();
        std::string warning;
        app.saved_settings = read_app_settings(app.settings_file, warning);
        if (!warning.empty()) app.say(warning, true);
        app.panel_width = app.saved_settings.panel_width;
    }
    loaded_from(app, options.scene_source);
    for (const std::string& note : scene.notes) app.say(note);  // the command line has printed them
    if (!options.record.empty()) app.recording = Recording{std::filesystem::absolute(options.record), 0, {}};
    renderer->set_cloth(app.sim);
    const float scale = window->content_scale();
    reset_camera(app, view_aspect(app, *window, scale));
    record_energy(app);
    const int exit_code = main_loop(*window, *renderer, app, options, scale);
    renderer.reset();
    return exit_code;
}

}  // namespace clothsim
