// What the panel's "Open" and scene combo do, apart from the window: load, validate and build a scene as
// one step, so a file that fails anywhere (unreadable, bad TOML, a bad value, pins outside the grid)
// changes nothing: the user's edited scene, the scene reset goes back to, and the running cloth stay.
#pragma once

#include "clothsim/mass_spring.hpp"
#include "clothsim/scene.hpp"

#include <optional>
#include <string>

namespace clothsim {

// On success replaces all three and returns nothing; on failure returns the message (file, line, field)
// and leaves them untouched.
std::optional<std::string> open_scene(const std::string& source, Scene& edited, Scene& loaded, MassSpring& sim);

// The scene as it runs, what "Save scene as" writes: the document (name, cloth and pins as edited) with
// the simulation's live settings, which only the simulation holds.
inline Scene running_scene(const Scene& document, const MassSpring& sim) {
    Scene running = document;
    running.settings = sim.settings();
    return running;
}

}  // namespace clothsim
