// The bundled scenes in the per-spring form they had before they moved to [material] (issue 14).
//
// Tests about per-spring behaviour (stability bounds with uniform masses, springs edited or switched off, the
// guard, golden hashes of the per-spring path) and the benchmarks whose recorded figures measured this
// workload load a scene through per_spring_scene(): the same cloth, pins, forces and colliders as the bundled
// file, with cloth.mass, springs.structural/shear/bending and integration.substeps as the file held them, so
// their results are those of the old files bit for bit (test_stepper.cpp checks it against hashes recorded
// before the move). A test about the bundled scene as a user sees it loads it with load_scene() instead.
#pragma once

#include "clothsim/material.hpp"
#include "clothsim/scene.hpp"

#include <array>
#include <string>
#include <string_view>

namespace clothsim {

// What each bundled file held before the move.
struct PerSpringForm {
    std::string_view scene;
    float mass;        // kg, the whole cloth
    float structural;  // N/m, each spring (both axes)
    float shear;       // N/m
    float bending;     // N/m, each skip-one spring (both axes)
    int substeps;      // per step: 0.67 to 0.68 of the critical substep
    float damping;     // 1/s
};
inline constexpr std::array<PerSpringForm, 6> kPerSpringForms = {{
    {"hanging", 0.5f, 400.0f, 40.0f, 10.0f, 34, 0.2f},
    {"drape-sphere", 0.6f, 400.0f, 40.0f, 5.0f, 38, 0.3f},
    {"drape-cube", 0.6f, 400.0f, 40.0f, 5.0f, 38, 0.3f},
    {"falling", 0.5f, 400.0f, 40.0f, 10.0f, 34, 0.3f},
    {"flag", 0.3f, 400.0f, 40.0f, 8.0f, 40, 0.1f},
    {"curtain", 0.8f, 400.0f, 40.0f, 4.0f, 36, 0.3f},
}};

inline const PerSpringForm* find_per_spring_form(std::string_view scene) {
    for (const PerSpringForm& f : kPerSpringForms) {
        if (f.scene == scene) return &f;
    }
    return nullptr;
}

// The bundled scene `name` switched to the per-spring form above. Throws SceneError for another name.
inline Scene per_spring_scene(std::string_view name) {
    const PerSpringForm* form = find_per_spring_form(name);
    if (!form) {
        throw SceneError("per_spring_scene: '" + std::string(name) +
                         "' has no recorded per-spring form; allowed: hanging, drape-sphere, drape-cube, falling, "
                         "flag, curtain");
    }
    Scene s = load_scene(name);
    s.material = MaterialSettings{};  // disabled: the fields below are what the solvers use
    s.per_spring_fields = kClothMass | kSpringsStructural | kSpringsShear | kSpringsBending;
    s.cloth.mass = form->mass;
    s.settings.springs.structural = glm::vec2(form->structural);
    s.settings.springs.shear = form->shear;
    s.settings.springs.bending = glm::vec2(form->bending);
    s.settings.integration.substeps = form->substeps;
    s.settings.springs.damping = form->damping;
    s.settings.springs.tether_strain = 0.0f;  // no file had tethers then
    return s;
}

// For the benchmarks' --scene: per_spring_scene() of a scene listed above, load_scene() of anything else (a
// file, or a scene that was born in the material form).
inline Scene load_per_spring(std::string_view name_or_path) {
    return find_per_spring_form(name_or_path) ? per_spring_scene(name_or_path) : load_scene(name_or_path);
}

}  // namespace clothsim
