#include "scene_loading.hpp"

#include "clothsim/mesh_file.hpp"

#include <cctype>
#include <cstdio>
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
        std::string extension = p.extension().string();
        for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (extension == ".obj") {
            choice.meshes.push_back(path);  // read (and refused, saying why) when added
            continue;
        }
        if (p.extension() != ".toml") why = "not a scene file (a scene file ends in .toml; a mesh to add, in .obj)";
        else if (std::filesystem::is_directory(p, ec)) why = "a folder, not a scene file";
        else if (!std::filesystem::is_regular_file(p, ec)) why = "no such file";
        else if (choice.open) why = "one scene at a time: " + *choice.open + " is opened";
        if (why.empty()) choice.open = path;
        else choice.refused.push_back("dropped " + path + ": not opened: " + why);
    }
    return choice;
}

std::string add_dropped_mesh(const std::string& path, glm::vec3 ground, MassSpring& sim) {
    MeshCollider mesh;
    try {
        mesh.mesh = read_mesh_file(path);
    } catch (const SceneError& e) {
        return "dropped " + path + ": not added: " + e.what();
    }
    mesh.file = std::filesystem::absolute(path).string();
    const glm::dvec3 lo = mesh.mesh->lo(), hi = mesh.mesh->hi(), middle = 0.5 * (lo + hi);
    mesh.position = glm::vec3(glm::dvec3(ground) - glm::dvec3(middle.x, lo.y, middle.z));
    SimulationSettings settings = sim.settings();
    settings.colliders.shapes.push_back(Collider::of(mesh));
    sim.apply(settings);
    const glm::dvec3 size = hi - lo;
    char where[160];
    std::snprintf(where, sizeof where, " at (%.3g, %.3g, %.3g), %.3g x %.3g x %.3g m", mesh.position.x, mesh.position.y,
                  mesh.position.z, size.x, size.y, size.z);
    return "added " + path + " (" + std::to_string(mesh.mesh->triangles().size()) + " triangles) as collider " +
           std::to_string(settings.colliders.shapes.size() - 1) + where;
}

}  // namespace clothsim
