#include "scene_loading.hpp"

#include <filesystem>
#include <system_error>

namespace clothsim {

std::optional<std::string> open_scene(const std::string& source, Scene& edited, Scene& loaded, MassSpring& sim) {
    try {
        Scene scene = load_scene(source);
        MassSpring built = build_simulation(scene);
        // Nothing below throws: the three change together or not at all.
        edited = scene;
        loaded = std::move(scene);
        sim = std::move(built);
        return std::nullopt;
    } catch (const SceneError& e) {
        return std::string(e.what());
    }
}

DropChoice choose_dropped_scene(const std::vector<std::string>& paths) {
    DropChoice choice;
    for (const std::string& path : paths) {
        std::error_code ec;
        const std::filesystem::path p(path);
        std::string why;
        if (p.extension() != ".toml") why = "not a scene file (a scene file ends in .toml)";
        else if (std::filesystem::is_directory(p, ec)) why = "a folder, not a scene file";
        else if (!std::filesystem::is_regular_file(p, ec)) why = "no such file";
        else if (choice.open) why = "one scene at a time: " + *choice.open + " is opened";
        if (why.empty()) choice.open = path;
        else choice.refused.push_back("dropped " + path + ": not opened: " + why);
    }
    return choice;
}

}  // namespace clothsim
