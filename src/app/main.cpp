// clothsim: command-line entry. Parses flags (CLI11), loads the scene and its --set overrides, then opens
// the desktop app, or runs headless. Exit codes: 0 ok, 2 bad input (or no display / OpenGL 3.3),
// 3 the simulation became non-finite, 4 an OpenGL error in a scripted (--frames) run.
#include "app.hpp"
#include "headless.hpp"

#include "clothsim/scene.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>

int main(int argc, char** argv) {
    using namespace clothsim;
    CLI::App app{"clothsim: a mass-spring cloth simulator"};
    app.get_formatter()->column_width(36);

    bool headless = false;
    std::string scene_name = "hanging";
    std::vector<std::string> overrides;
    HeadlessOptions options;
    bool list_scenes = false, list_fields = false, print_scene = false;
    AppOptions app_options;
    std::string size_text;

    auto* headless_flag = app.add_flag("--headless", headless, "Simulate without a window and report on stdout");
    app.add_option("--scene", scene_name, "Bundled scene name or path to a .toml scene file")->capture_default_str();
    auto* duration = app.add_option("--duration", options.duration, "Simulated seconds to run (default 1)")
                         ->check(CLI::PositiveNumber);
    auto* steps = app.add_option("--steps", options.steps, "Steps of integration.dt to run")->check(CLI::NonNegativeNumber);
    duration->excludes(steps);
    app.add_option("--set", overrides, "Override a scene field: key=value (repeatable; see --list-fields)")
        ->take_all()
        ->allow_extra_args(false);
    auto* trajectory = app.add_option("--trajectory", options.trajectory, "Write positions as CSV (step,time,particle,x,y,z)");
    app.add_option("--every", options.every, "With --trajectory: record every K steps")
        ->check(CLI::Range(1LL, 1000000000LL))
        ->needs(trajectory);
    app.add_option("--obj", options.obj, "Write the final mesh as Wavefront OBJ");
    app.add_flag("--json", options.json, "Print one JSON object with the run's figures on stdout");
    app.add_option("--auto-substeps", options.auto_substeps,
                   "Choose integration.substeps so the substep is this fraction of the critical one (the app "
                   "does this by default at 0.5, except in --frames runs)")
        ->check(CLI::Range(0.01f, 1.0f));
    app.add_flag("--guard", options.guard,
                 "Headless: when a step blows up, roll back, double integration.substeps and retry (says so)");
    app.add_flag("--list-scenes", list_scenes, "List the bundled scenes and exit");
    app.add_flag("--list-fields", list_fields, "List every scene field with its unit and allowed values, and exit");
    app.add_flag("--print-scene", print_scene, "Print the scene (after --set) as TOML and exit");
    auto* frames = app.add_option("--frames", app_options.frames, "App: run N frames (one step each), then exit")
                       ->check(CLI::PositiveNumber);
    app.add_option("--screenshot", app_options.screenshot, "App: with --frames, write the last frame as PNG")
        ->needs(frames);
    app.add_flag("--paused", app_options.start_paused, "App: start paused (Space or Play runs, S steps once)")
        ->excludes(headless_flag);
    app.add_option("--quit-after", app_options.quit_after, "App: close the window after this many wall seconds")
        ->check(CLI::PositiveNumber)
        ->excludes(frames)
        ->excludes(headless_flag);
    app.add_option("--size", size_text, "App: window size WxH in screen coordinates (default 1280x720)");
    std::vector<std::string> view_items;
    app.add_option("--view", view_items,
                   "App: start with these view options (comma-separated): wireframe, springs=kind, springs=strain, "
                   "particles, no-pins, no-texture, no-shadows, no-panel")
        ->delimiter(',');

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "clothsim: error: " << e.what() << "\n(run clothsim --help for the flags)\n";
        return kExitBadInput;
    }

    if (list_scenes) {
        for (const std::string& name : bundled_scene_names()) std::cout << name << "\n";
        return kExitOk;
    }
    if (list_fields) {
        for (const FieldInfo& f : scene_fields()) {
            std::cout << f.name << (f.unit.empty() ? "" : " (" + std::string(f.unit) + ")") << ": " << f.help
                      << "; allowed: " << describe_allowed(f) << "; default: " << format_value(Scene{}, f) << "\n";
        }
        return kExitOk;
    }

    try {
        Scene scene = load_scene(scene_name);
        for (const std::string& assignment : overrides) apply_override(scene, assignment);
        if (print_scene) {
            std::cout << to_toml(scene);
            return kExitOk;
        }
        if (headless) return run_headless(scene, options);
        if (!size_text.empty()) {
            int w = 0, h = 0;
            char tail = 0;
            if (std::sscanf(size_text.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 64 || h < 64 || w > 8192 ||
                h > 8192) {
                std::cerr << "clothsim: error: --size " << size_text
                          << ": expected WIDTHxHEIGHT, each in [64, 8192], e.g. 1280x720\n";
                return kExitBadInput;
            }
            app_options.size = {w, h};
        }
        for (const std::string& item : view_items) {
            if (!apply_view_option(app_options.view, app_options.show_panel, item)) {
                std::cerr << "clothsim: error: --view " << item
                          << ": unknown view option; allowed: wireframe, springs=kind, springs=strain, particles, "
                             "no-pins, no-texture, no-shadows, no-panel\n";
                return kExitBadInput;
            }
        }
        app_options.scene_source = scene_name;
        // Interactive runs pick substeps from the stability limit; scripted ones (--frames) step what the
        // scene says, so a test can reproduce them, unless --auto-substeps asks otherwise.
        app_options.auto_substeps = options.auto_substeps > 0.0f || !app_options.frames;
        if (options.auto_substeps > 0.0f) app_options.safety = options.auto_substeps;
        return run_app(scene, app_options);
    } catch (const SceneError& e) {
        std::cerr << "clothsim: error: " << e.what() << "\n";
        return kExitBadInput;
    }
}
