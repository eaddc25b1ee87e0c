// What the panel's "Open" and scene combo do, apart from the window: load, validate and build a scene as
// one step, so a file that fails anywhere (unreadable, bad TOML, a bad value, pins outside the grid)
// changes nothing: the user's edited scene, the scene reset goes back to, and the running cloth stay.
#pragma once

#include "clothsim/mass_spring.hpp"
#include "clothsim/scene.hpp"

#include <optional>
#include <string>
#include <vector>

namespace clothsim {

// On success replaces all three and returns nothing; on failure returns the message (file, line, field)
// and leaves them untouched.
std::optional<std::string> open_scene(const std::string& source, Scene& edited, Scene& loaded, MassSpring& sim);

// What a drop of files onto the window does: the first regular file ending in .toml is opened (through
// open_scene, like "Open file"); each .obj file is added as a mesh collider (add_dropped_mesh); every other
// file is refused with the reason, and nothing else changes.
struct DropChoice {
    std::optional<std::string> open;  // the file to open
    std::vector<std::string> meshes;  // the .obj files to add as colliders, in the drop's order
    std::vector<std::string> refused; // one message per file not opened
};
DropChoice choose_dropped_scene(const std::vector<std::string>& paths);

// Adds the OBJ file `path` to the running simulation as a mesh collider standing on `ground` (the point under
// the cursor on the floor): its lowest point on the floor, the middle of its box over the point, at the file's
// scale (OBJ units taken as metres), with the mesh kind's friction. Returns the message for the user: what was
// added and where, or (nothing added) why the file was refused, naming the file and line.
std::string add_dropped_mesh(const std::string& path, glm::vec3 ground, MassSpring& sim);

// The scene as it runs, what "Save scene as" writes: the document (name, cloth and pins as edited) with
// the simulation's live settings, which only the simulation holds.
inline Scene running_scene(const Scene& document, const MassSpring& sim) {
    Scene running = document;
    running.settings = sim.settings();
    return running;
}

}  // namespace clothsim
