// clothsim: command-line entry. Parses flags (CLI11), loads the scene and its --set overrides, then opens
// the desktop app, or runs headless. Exit codes: exit_codes.hpp.
#include "app.hpp"
#include "exit_codes.hpp"
#include "headless.hpp"

#include "clothsim/cloth_mesh.hpp"
#include "clothsim/mass_spring.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>

namespace {

using namespace clothsim;

// Everything the command line says, before any scene is loaded.
struct CommandLine {
    bool headless = false;
    std::string scene_name = "hanging";
    std::string scene_argument;  // the positional SCENE (what a file manager passes: clothsim FILE)
    std::vector<std::string> overrides;
    HeadlessOptions options;
    bool list_scenes = false, list_fields = false, print_scene = false;
    AppOptions app_options;
    std::string size_text;
    std::vector<std::string> view_items;
};

// What a numeric flag allows, for its check and its message: "a number > 0 (simulated seconds)".
struct NumberRule {
    bool whole = false;           // an integer
    double min = 0.0;
    bool min_excluded = false;    // > min rather than >= min
    double max = std::numeric_limits<double>::infinity();
    const char* meaning = "";     // what the number counts
};

// "> 0", ">= 0" or "in [1, 1000000000]" (%.10g: every bound here prints in full).
std::string bounds_text(const NumberRule& rule) {
    char text[80];
    if (std::isfinite(rule.max)) {
        std::snprintf(text, sizeof text, "in %c%.10g, %.10g]", rule.min_excluded ? '(' : '[', rule.min, rule.max);
    } else {
        std::snprintf(text, sizeof text, "%s %.10g", rule.min_excluded ? ">" : ">=", rule.min);
    }
    return text;
}

// A CLI11 transform whose message says what is allowed in one short line, after CLI11's "--FLAG: ", e.g.
// "-1 is out of range: must be a number > 0 (simulated seconds)": CLI11's PositiveNumber and NonNegativeNumber
// print their upper end, DBL_MAX, as a 309-digit number, and call "abc" out of range too. A whole number is
// read in base 10 and handed on in plain decimal (a transform may rewrite the text; a check may not): CLI11
// reads integers with strtoll base 0, which takes "010" for 8.
CLI::Validator number_check(const NumberRule& rule) {
    const std::string allowed = std::string("must be ") + (rule.whole ? "a whole number " : "a number ") +
                                bounds_text(rule) + " (" + rule.meaning + ")";
    return CLI::Validator(
        [rule, allowed](std::string& text) -> std::string {
            const std::string shown = text.size() <= 16 ? text : text.substr(0, 13) + "...";  // a short line
            const char* begin = text.c_str();
            char* end = nullptr;
            errno = 0;
            double value = 0.0;
            if (rule.whole) {
                const long long whole = std::strtoll(begin, &end, 10);
                if (end == begin || *end != '\0') {
                    const double number = std::strtod(begin, &end);
                    if (end == begin || *end != '\0') return "'" + shown + "' is not a number: " + allowed;
                    const char* why = number == std::trunc(number) ? "in plain digits" : "a whole number";
                    return "'" + shown + "' is not " + why + ": " + allowed;
                }
                if (errno == ERANGE) return shown + " is out of range: " + allowed;
                text = std::to_string(whole);
                value = static_cast<double>(whole);
            } else {
                value = std::strtod(begin, &end);
                if (end == begin || *end != '\0') return "'" + shown + "' is not a number: " + allowed;
                if (!std::isfinite(value)) return shown + " is not a finite number: " + allowed;
            }
            const bool above_min = rule.min_excluded ? value > rule.min : value >= rule.min;
            if (!above_min || value > rule.max) return shown + " is out of range: " + allowed;
            return "";
        },
        bounds_text(rule));
}

// The flags (CLI11), bound to `cl`.
void add_flags(CLI::App& app, CommandLine& cl) {
    auto* headless_flag = app.add_flag("--headless", cl.headless, "Simulate without a window and report on stdout");
    auto* scene = app.add_option("--scene", cl.scene_name, "Bundled scene name or path to a .toml scene file")
                      ->capture_default_str();
    app.add_option("scene", cl.scene_argument, "The same as --scene: a bundled scene name or a .toml file")
        ->excludes(scene);
    auto* duration = app.add_option("--duration", cl.options.duration, "Simulated seconds to run (default 1)")
                         ->transform(number_check({.min_excluded = true, .meaning = "simulated seconds"}));
    auto* steps = app.add_option("--steps", cl.options.steps, "Steps of integration.dt to run")
                      ->transform(number_check({.whole = true, .meaning = "steps of integration.dt"}));
    duration->excludes(steps);
    app.add_option("--set", cl.overrides, "Override a scene field: key=value (repeatable; see --list-fields)")
        ->take_all()
        ->allow_extra_args(false);
    auto* trajectory = app.add_option("--trajectory", cl.options.trajectory, "Write positions as CSV (step,time,particle,x,y,z)");
    app.add_option("--every", cl.options.every, "With --trajectory: record every K steps")
        ->transform(number_check({.whole = true, .min = 1, .max = 1e9, .meaning = "steps between rows"}))
        ->needs(trajectory);
    CLI::Option* obj = app.add_option("--obj", cl.options.obj, "Write the final mesh as Wavefront OBJ");
    app.add_flag("--obj-colliders", cl.options.obj_colliders,
                 "With --obj: write the colliders too, each as its own object after the cloth")
        ->needs(obj);
    app.add_flag("--json", cl.options.json, "Print one JSON object with the run's figures on stdout");
    app.add_option("--auto-substeps", cl.options.auto_substeps,
                   "Choose integration.substeps so the substep is this fraction of the critical one (the app "
                   "does this by default at 0.5, except in --frames runs)")
        ->transform(number_check({.min = 0.01, .max = 1, .meaning = "x the critical substep"}));
    auto* settle = app.add_flag("--settle", cl.options.settle,
                                "Headless: settle the cloth to rest (kinetic damping) until its residual, the largest net "
                                "force on a particle over its weight, falls below --settle-tolerance; --duration or "
                                "--steps limit it (default 30 s); exit 5 if it does not settle")
                       ->needs(headless_flag);
    app.add_option("--settle-tolerance", cl.options.settle_tolerance, "With --settle: the residual that counts as settled (default 0.01)")
        ->transform(number_check({.min_excluded = true, .max = 1, .meaning = "x a particle's weight"}))
        ->needs(settle);
    app.add_flag("--guard", cl.options.guard,
                 "Headless: when a step blows up, roll back, double integration.substeps and retry (says so)");
    app.add_flag("--list-scenes", cl.list_scenes, "List the bundled scenes and exit");
    app.add_flag("--list-fields", cl.list_fields, "List every scene field with its unit and allowed values, and exit");
    app.add_flag("--print-scene", cl.print_scene, "Print the scene (after --set) as TOML and exit");
    auto* frames = app.add_option("--frames", cl.app_options.frames, "App: run N frames (one step each), then exit")
                       ->transform(number_check({.whole = true, .min = 1, .meaning = "frames of one step each"}));
    app.add_option("--screenshot", cl.app_options.screenshot, "App: with --frames, write the last frame as PNG")
        ->needs(frames);
    app.add_option("--record", cl.app_options.record,
                   "App: with --frames, write every frame as DIR/frame-000001.png, ... (created if missing)")
        ->needs(frames);
    app.add_option("--frame-times", cl.app_options.frame_times,
                   "App: write a CSV row per frame as it ends: milliseconds (frame, simulation, render), substeps, and the cloth (time, max_move, max_speed, mean_strain, kinetic_energy, centroid)")
        ->excludes(headless_flag);
    app.add_flag("--paused", cl.app_options.start_paused, "App: start paused (Space or Play runs, S steps once)")
        ->excludes(headless_flag);
    app.add_option("--quit-after", cl.app_options.quit_after, "App: close the window after this many wall seconds")
        ->transform(number_check({.min_excluded = true, .meaning = "wall seconds"}))
        ->excludes(frames)
        ->excludes(headless_flag);
    app.add_option("--samples", cl.app_options.samples,
                   "App: anti-aliasing samples per pixel, 0 (off) to 16 (default: 4, or 0 on a software OpenGL "
                   "renderer such as llvmpipe)")
        ->transform(number_check({.whole = true, .min = 0, .max = 16, .meaning = "samples per pixel"}))
        ->excludes(headless_flag);
    app.add_option("--size", cl.size_text, "App: window size WxH in screen coordinates (default 1280x720)");
    app.add_option("--view", cl.view_items,
                   "App: start with these view options (comma-separated): wireframe, springs=kind, springs=strain, "
                   "particles, no-pins, no-texture, no-shadows, no-panel")
        ->delimiter(',')
        ->allow_extra_args(false);  // clothsim --view wireframe SCENE: SCENE is the scene
}

// --list-scenes and --list-fields; returns true when one was given (and printed).
bool print_lists(const CommandLine& cl) {
    if (cl.list_scenes) {
        for (const std::string& name : bundled_scene_names()) std::cout << name << "\n";
        return true;
    }
    if (cl.list_fields) {
        for (const FieldInfo& f : scene_fields()) {
            std::cout << f.name << (f.unit.empty() ? "" : " (" + std::string(f.unit) + ")") << ": " << f.help
                      << "; allowed: " << describe_allowed(f) << "; default: " << format_value(Scene{}, f) << "\n";
        }
        // Each collider kind's fields, as a [[colliders.shapes]] entry (kind = "...") holds them.
        for (std::size_t kind = 0; kind < kColliderKindCount; ++kind) {
            for (const ColliderField& f : collider_fields_of_kind(kind)) {
                std::cout << "colliders.shapes[kind = " << collider_kind_names()[kind] << "]." << f.name
                          << (f.unit.empty() ? "" : " (" + std::string(f.unit) + ")") << ": " << f.help
                          << "; allowed: " << describe_allowed(f) << "; default: " << format_value(f) << "\n";
            }
        }
        return true;
    }
    return false;
}

// The app's options from --size, --view and --auto-substeps; an error message, or "".
std::string make_app_options(CommandLine& cl) {
    AppOptions& app_options = cl.app_options;
    if (!cl.size_text.empty()) {
        int w = 0, h = 0;
        char tail = 0;
        if (std::sscanf(cl.size_text.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 64 || h < 64 || w > 8192 ||
            h > 8192) {
            return "--size " + cl.size_text + ": expected WIDTHxHEIGHT, each in [64, 8192], e.g. 1280x720";
        }
        app_options.size = {w, h};
    }
    for (const std::string& item : cl.view_items) {
        if (!apply_view_option(app_options.view, app_options.show_panel, item)) {
            return "--view " + item +
                   ": unknown view option; allowed: wireframe, springs=kind, springs=strain, particles, no-pins, "
                   "no-texture, no-shadows, no-panel";
        }
    }
    app_options.scene_source = cl.scene_name;
    // Interactive runs pick substeps from the stability limit; scripted ones (--frames) step what the scene
    // says, so a test can reproduce them, unless --auto-substeps asks otherwise.
    app_options.auto_substeps = cl.options.auto_substeps > 0.0f || !app_options.frames;
    if (cl.options.auto_substeps > 0.0f) app_options.safety = cl.options.auto_substeps;
    return "";
}

// Loads the scene with its --set overrides, then prints it, runs it headless or opens the app.
int run(CommandLine& cl) {
    if (!cl.scene_argument.empty()) cl.scene_name = cl.scene_argument;
    Scene scene = load_scene(cl.scene_name);
    for (const std::string& assignment : cl.overrides) apply_override(scene, assignment);
    for (const std::string& note : scene.notes) std::cerr << "clothsim: note: " << note << "\n";
    if (cl.print_scene) {
        if (scene.cloth.is_mesh()) {
            const MassSpring sim = build_simulation(scene);
            std::cout << "# " << cloth_mesh_summary(sim.topology(), sim.particle_count(), stability_limit(sim).critical_substep)
                      << "\n";
        }
        std::cout << to_toml(scene);
        return kExitOk;
    }
    if (cl.headless) return run_headless(scene, cl.options);
    if (const std::string error = make_app_options(cl); !error.empty()) {
        std::cerr << "clothsim: error: " << error << "\n";
        return kExitBadInput;
    }
    return run_app(scene, cl.app_options);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"clothsim: a mass-spring cloth simulator"};
    app.get_formatter()->column_width(36);
    CommandLine cl;
    add_flags(app, cl);
    app.set_version_flag("--version", std::string("clothsim ") + CLOTHSIM_VERSION + " (fast solver kernel: " +
                                          MassSpring::fast_kernel_name() + ")");
    try {
        app.parse(argc, argv);
    } catch (const CLI::Success& e) {  // --help, --version
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "clothsim: error: " << e.what() << "\n(run clothsim --help for the flags)\n";
        return kExitBadInput;
    }
    if (print_lists(cl)) return kExitOk;
    try {
        return run(cl);
    } catch (const SceneError& e) {
        std::cerr << "clothsim: error: " << e.what() << "\n";
        return kExitBadInput;
    }
}
