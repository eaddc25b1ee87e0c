// The app's main loop, one straight function as in Dear ImGui's example_glfw_opengl3: poll input, step the
// simulation at a fixed dt, draw the scene, draw the panel, act on what the panel asked.
#include "app.hpp"

#include "app_state.hpp"
#include "camera.hpp"
#include "gl.hpp"
#include "layout.hpp"
#include "picking.hpp"
#include "renderer.hpp"
#include "scene_loading.hpp"
#include "shader.hpp"
#include "window.hpp"

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
#include <cerrno>
#include <chrono>
#include <cstring>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <vector>

#ifndef CLOTHSIM_DEFAULT_TEXTURE_DIR
#define CLOTHSIM_DEFAULT_TEXTURE_DIR "assets/textures"
#endif

namespace clothsim {
namespace {

using Clock = std::chrono::steady_clock;

std::filesystem::path texture_directory() {
    return data_directory("CLOTHSIM_TEXTURES", CLOTHSIM_DEFAULT_TEXTURE_DIR);
}

// The 3D view: the window right of the panel, in window coordinates (x, y from the top-left, w, h).
glm::vec4 view_rect(const AppState& app, const Window& window, float scale) {
    return clothsim::view_rect(glm::vec2(window.window_size()), panel_width(app, scale));
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

// What a new cloth resets: the grab, the accumulator, the plots, the renderer's buffers.
void after_rebuild(AppState& app, Renderer& renderer) {
    app.grab.reset();
    app.accumulator = 0.0;
    app.stats.kinetic.clear();
    app.stats.potential.clear();
    app.stats.total.clear();
    renderer.set_cloth(app.sim);
}

// Builds a new simulation from app.scene; on a bad scene keeps the old one and says why.
bool rebuild(AppState& app, Renderer& renderer) {
    try {
        app.sim = build_simulation(app.scene);
    } catch (const SceneError& e) {
        app.say(std::string("not rebuilt: ") + e.what(), true);
        return false;
    }
    after_rebuild(app, renderer);
    return true;
}

// Fixed-step physics: whole steps of integration.dt for the wall time that passed (scaled), at most
// max_catchup_steps per frame so a slow frame slows the simulation instead of spiralling.
void simulate(AppState& app, double wall_seconds, bool scripted) {
    app.sim.settings() = app.scene.settings;
    // The limit depends on the settings, masses and pins: a resting cloth has had none of them change.
    if (!app.sim.resting()) app.limit = stability_limit(app.sim);
    if (app.auto_substeps) {
        const int n = auto_substeps(app.limit, app.scene.settings.integration.dt, app.safety);
        app.scene.settings.integration.substeps = n;
        app.sim.settings().integration.substeps = n;
    }
    const double dt = app.scene.settings.integration.dt;
    long long steps = 0;
    if (scripted) {
        steps = app.paused ? 0 : 1;
    } else if (app.step_once) {
        steps = 1;
    } else if (!app.paused) {
        app.accumulator += wall_seconds * app.time_scale;
        steps = static_cast<long long>(app.accumulator / dt);
        if (steps > app.max_catchup_steps) {
            app.stats.dropped_seconds += (steps - app.max_catchup_steps) * dt;
            steps = app.max_catchup_steps;
            app.accumulator = 0.0;
        } else {
            app.accumulator -= steps * dt;
        }
    }
    app.step_once = false;
    const auto start = Clock::now();
    app.sim.reset_profile();
    const bool was_resting = app.sim.resting();
    if (steps > 0 && (was_resting || app.sim.all_finite())) {
        // The guard: a step that blows up is rolled back and retried with twice the substeps; the user is told.
        std::string log;
        const bool ok = run_guarded(app.sim, steps, GuardSettings{}, log);
        if (!log.empty()) {
            app.scene.settings.integration.substeps = app.sim.settings().integration.substeps;
            if (app.auto_substeps) {
                app.auto_substeps = false;
                log += "auto substeps turned off to keep the guard's choice\n";
            }
            app.say(log, !ok);
        }
        if (!ok) {
            app.paused = true;
            app.say(log + "paused at the last good state: lower integration.dt or soften the springs, then play", true);
        }
        if (was_resting && app.sim.resting()) {
            // Nothing moved: the plots go on with the same values instead of recomputing them.
            app.stats.kinetic.push(app.stats.kinetic.last());
            app.stats.potential.push(app.stats.potential.last());
            app.stats.total.push(app.stats.total.last());
        } else {
            record_energy(app);
        }
    }
    app.stats.profile = app.sim.profile();
    app.stats.sim_ms = std::chrono::duration<float, std::milli>(Clock::now() - start).count();
    app.stats.substeps_last_frame = steps * app.scene.settings.integration.substeps;
}

Ray cursor_ray(const AppState& app, const Window& window, float scale) {
    double x = 0.0, y = 0.0;
    glfwGetCursorPos(window.get(), &x, &y);
    const glm::vec4 r = view_rect(app, window, scale);
    return ray_through(app.camera, glm::vec2(x - r.x, y - r.y), glm::vec2(r.z, r.w));
}

// Converts the pins of the running simulation to the scene's explicit list, so "Save scene" keeps them.
void pins_to_scene(AppState& app) {
    const int cols = app.sim.topology().cols;  // the running cloth, even if an edit of the grid failed to rebuild
    app.scene.pins.preset = PinPreset::None;
    app.scene.pins.particles.clear();
    for (std::size_t i = 0; i < app.sim.particle_count(); ++i) {
        if (app.sim.state().pinned[i] && !(app.grab && app.grab->particle == i && !app.grab->was_pinned)) {
            app.scene.pins.particles.emplace_back(static_cast<int>(i) / cols, static_cast<int>(i) % cols);
        }
    }
}

void handle_mouse(AppState& app, const Window& window, float scale) {
    const ImGuiIO& io = ImGui::GetIO();
    const glm::vec2 delta(io.MouseDelta.x, io.MouseDelta.y);
    const float height = static_cast<float>(window.window_size().y);
    if (app.grab) {
        if (ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
            if (auto p = intersect_plane(cursor_ray(app, window, scale), app.grab->plane_point, app.grab->plane_normal)) {
                app.sim.move_pinned(app.grab->particle, *p);
            }
        } else {
            if (!app.grab->was_pinned) app.sim.set_pinned(app.grab->particle, false);
            app.grab.reset();
        }
        return;
    }
    if (io.WantCaptureMouse) return;
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift) {
        const std::vector<glm::vec3> positions = app.sim.positions();
        const auto hit = pick_particle(cursor_ray(app, window, scale), positions, pick_spread(app.camera, 10.0f, height));
        if (hit && io.KeyCtrl) {
            const bool pinned = !app.sim.particle(*hit).pinned;
            app.sim.set_pinned(*hit, pinned);
            pins_to_scene(app);
            app.say("particle " + std::to_string(*hit) + (pinned ? " pinned" : " unpinned"));
        } else if (hit) {
            app.grab = Grab{*hit, app.sim.particle(*hit).pinned, positions[*hit], -app.camera.forward()};
            app.sim.set_pinned(*hit, true);
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
}

// Key presses collected by a GLFW callback. ImGui 1.86 (before its 1.87 input queue) sees only the key
// state at each frame, so a tap shorter than a frame would be lost; the queue keeps every press.
struct KeyQueue {
    std::vector<int> pressed;
};

void on_key(GLFWwindow* window, int key, int, int action, int) {
    if (action != GLFW_PRESS) return;
    if (auto* queue = static_cast<KeyQueue*>(glfwGetWindowUserPointer(window))) queue->pressed.push_back(key);
}

void handle_keys(AppState& app, KeyQueue& keys, PanelRequests& requests) {
    const std::vector<int> pressed_keys = std::move(keys.pressed);
    keys.pressed.clear();
    if (ImGui::GetIO().WantCaptureKeyboard) return;
    auto pressed = [&](int key) {
        return std::find(pressed_keys.begin(), pressed_keys.end(), key) != pressed_keys.end();
    };
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
    if (pressed(GLFW_KEY_F12)) requests.screenshot = true;
    if (pressed(GLFW_KEY_ESCAPE)) requests.quit = true;
}

// Atomic (atomic_file.hpp): a failed save leaves the old file as it was and says why.
bool save_scene(AppState& app, const std::string& path) {
    std::string error;
    if (!write_file_atomically(path, to_toml(app.scene), error)) {
        app.say("not saved: " + error, true);
        return false;
    }
    app.say("saved " + path);
    return true;
}

void apply_requests(AppState& app, Renderer& renderer, const Window& window, float scale, PanelRequests& requests) {
    const float aspect = view_aspect(app, window, scale);
    if (requests.load) {
        // Loaded and built in one step: a rejected file keeps the user's edits and the running cloth.
        if (auto error = open_scene(*requests.load, app.scene, app.loaded, app.sim)) {
            app.say(*error, true);
        } else {
            app.scene_source = *requests.load;
            after_rebuild(app, renderer);
            reset_camera(app, aspect);
            app.say("loaded " + *requests.load);
        }
    }
    if (requests.reset) {
        app.scene = app.loaded;
        if (rebuild(app, renderer)) app.say("reset to the start of " + app.scene.name);
    }
    if (requests.rebuild) rebuild(app, renderer);
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
    char name[64];
    std::strftime(name, sizeof name, "clothsim-%Y%m%d-%H%M%S.png", std::localtime(&now));
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

int run_app(const Scene& scene, const AppOptions& options) {
    const bool scripted = options.frames.has_value();
    std::optional<Window> window;
    try {
        window.emplace(options.size, "clothsim - " + scene.name, !scripted);
    } catch (const WindowError& e) {
        std::cerr << "clothsim: error: " << e.what() << "\n";
        return 2;
    }
    if (scripted && !options.screenshot.empty()) {
        const auto parent = std::filesystem::path(options.screenshot).parent_path();
        if (!parent.empty() && !std::filesystem::is_directory(parent)) {
            std::cerr << "clothsim: error: --screenshot " << options.screenshot << ": the directory does not exist\n";
            return 2;
        }
    }

    std::optional<Renderer> renderer;
    try {
        renderer.emplace(gl::shader_directory(), texture_directory());
    } catch (const std::exception& e) {
        std::cerr << "clothsim: error: " << e.what() << "\n";
        return 2;
    }

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // the layout is fixed; nothing to litter the working directory with
    const float scale = window->content_scale();
    ImFontConfig font;
    font.SizePixels = 13.0f * scale;
    io.Fonts->AddFontDefault(&font);
    ImGui::StyleColorsDark();
    ImGui::GetStyle().ScaleAllSizes(scale);
    // Installed before ImGui's, which chains to it.
    KeyQueue keys;
    glfwSetWindowUserPointer(window->get(), &keys);
    glfwSetKeyCallback(window->get(), on_key);
    ImGui_ImplGlfw_InitForOpenGL(window->get(), true);
    ImGui_ImplOpenGL3_Init("#version 330 core");

    AppState app(scene, options.scene_source);
    app.auto_substeps = options.auto_substeps;
    app.paused = options.start_paused;
    app.safety = options.safety;
    app.view = options.view;
    app.show_panel = options.show_panel;
    app.save_path = scene.name + "-edited.toml";
    app.open_path = std::filesystem::absolute(options.scene_source.ends_with(".toml")
                                                  ? std::filesystem::path(options.scene_source)
                                                  : scene_directory() / (options.scene_source + ".toml"))
                        .string();
    renderer->set_cloth(app.sim);
    reset_camera(app, view_aspect(app, *window, scale));
    record_energy(app);

    int exit_code = 0;
    long long frame = 0;
    bool vsync_applied = !scripted;
    auto last = Clock::now();
    const auto started = last;
    while (!glfwWindowShouldClose(window->get())) {
        glfwPollEvents();
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();

        PanelRequests requests;
        handle_keys(app, keys, requests);
        handle_mouse(app, *window, scale);

        const auto now = Clock::now();
        simulate(app, std::chrono::duration<double>(now - last).count(), scripted);
        last = now;

        const auto render_start = Clock::now();
        const glm::ivec2 fb = window->framebuffer_size();
        std::optional<std::size_t> grabbed;
        if (app.grab) grabbed = app.grab->particle;
        const glm::vec4 rect = view_rect(app, *window, scale);
        const float to_pixels = float(fb.x) / float(std::max(window->window_size().x, 1));
        const glm::ivec4 viewport(glm::round(rect.x * to_pixels), 0, glm::round(rect.z * to_pixels), fb.y);
        renderer->draw({app.sim, app.camera, fb, viewport, app.view, grabbed});
        const Renderer::ClothTimings& cloth = renderer->cloth_timings();
        app.stats.cloth_uploaded = cloth.cloth_uploaded;
        app.stats.times.add_frame(app.stats.profile, cloth.normals_ms, cloth.upload_ms);
        if (app.show_panel) {
            PanelRequests panel = draw_panel(app, scale);
            requests.rebuild |= panel.rebuild;
            requests.reset |= panel.reset;
            requests.frame_camera |= panel.frame_camera;
            requests.reset_camera |= panel.reset_camera;
            requests.screenshot |= panel.screenshot;
            requests.quit |= panel.quit;
            if (panel.load) requests.load = panel.load;
            if (panel.save) requests.save = panel.save;
        }
        ImGui::Render();
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        app.stats.render_ms = std::chrono::duration<float, std::milli>(Clock::now() - render_start).count();

        ++frame;
        // A GL error is a bug in the renderer: scripted runs (the tests) fail on it; interactive ones say so.
        if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
            char text[96];
            std::snprintf(text, sizeof text, "OpenGL error 0x%04X in frame %lld", error, frame);
            if (scripted) {
                std::cerr << "clothsim: error: " << text << "\n";
                exit_code = 4;
                break;
            }
            app.say(text, true);
        }
        if (scripted && frame >= *options.frames) {
            if (!options.screenshot.empty()) {
                const std::string error = write_screenshot(options.screenshot, fb.x, fb.y);
                if (!error.empty()) {
                    std::cerr << "clothsim: error: " << error << "\n";
                    exit_code = 2;
                } else {
                    std::cout << "wrote " << options.screenshot << " (" << fb.x << "x" << fb.y << ", frame " << frame
                              << ")\n";
                }
            }
            break;
        }
        if (requests.screenshot) {
            const std::string path = timestamped_screenshot_name();
            const std::string error = write_screenshot(path, fb.x, fb.y);
            app.say(error.empty() ? "screenshot saved to " + std::filesystem::absolute(path).string() : error,
                    !error.empty());
        }
        if (!scripted && app.vsync != vsync_applied) {
            window->set_vsync(app.vsync);
            vsync_applied = app.vsync;
        }
        glfwSwapBuffers(window->get());
        if (options.quit_after && std::chrono::duration<double>(Clock::now() - started).count() >= *options.quit_after) {
            requests.quit = true;
        }
        if (requests.quit) glfwSetWindowShouldClose(window->get(), GLFW_TRUE);
        apply_requests(app, *renderer, *window, scale, requests);
    }

    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    renderer.reset();
    return exit_code;
}

}  // namespace clothsim
