#include "scene_loading.hpp"

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

}  // namespace clothsim
