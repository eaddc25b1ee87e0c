// clothsim: command-line entry. Parses flags (CLI11), loads the scene and its --set overrides, then runs
// headless. Exit codes: 0 ok, 2 bad input, 3 the simulation became non-finite.
#include "headless.hpp"

#include "clothsim/scene.hpp"

#include <CLI/CLI.hpp>

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

    app.add_flag("--headless", headless, "Simulate without a window and report on stdout");
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
    app.add_flag("--list-scenes", list_scenes, "List the bundled scenes and exit");
    app.add_flag("--list-fields", list_fields, "List every scene field with its unit and allowed values, and exit");
    app.add_flag("--print-scene", print_scene, "Print the scene (after --set) as TOML and exit");

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
        if (!headless) {
            std::cerr << "clothsim: error: the desktop app is not built yet; run with --headless\n";
            return kExitBadInput;
        }
        return run_headless(scene, options);
    } catch (const SceneError& e) {
        std::cerr << "clothsim: error: " << e.what() << "\n";
        return kExitBadInput;
    }
}
