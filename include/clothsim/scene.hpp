// Scenes: the TOML files in assets/scenes/, the `--set key=value` overrides, and the builder that turns a
// Scene into a running MassSpring. The app, the tests and the benchmarks all build cloth through
// build_simulation(), so they simulate exactly the same thing.
#pragma once

#include "clothsim/mass_spring.hpp"
#include "clothsim/settings.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace clothsim {

struct ShapeMask;

// A scene that cannot be loaded, overridden or built. The message names the source (file and line, or the
// --set flag), the field, the value and what is allowed.
class SceneError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// ---- The field table: every scene field's dotted name, unit, valid range and meaning, in one place. ----
using FieldRef = std::variant<int*, float*, bool*, glm::vec2*, glm::vec3*, std::string*, PinSpec*, StretchCurve*,
                              WindModel*, SolverMethod*, Integrator*, ContactModel*, ClothShape*, MembraneModel*>;
using ConstFieldRef = std::variant<const int*, const float*, const bool*, const glm::vec2*, const glm::vec3*,
                                   const std::string*, const PinSpec*, const StretchCurve*, const WindModel*,
                                   const SolverMethod*, const Integrator*, const ContactModel*, const ClothShape*,
                                   const MembraneModel*>;

struct FieldInfo {
    std::string_view name;  // dotted name, as in the scene file and --set
    std::string_view unit;  // "" when dimensionless
    double min;             // valid range (inclusive), per component for vectors
    double max;
    std::string_view help;  // one line
    FieldRef (*ref)(Scene&);
    // The field of a scene that is only read.
    ConstFieldRef read(const Scene& scene) const;
};

std::span<const FieldInfo> scene_fields();
const FieldInfo* find_field(std::string_view name);
// "allowed values" of a field, as written in messages and in the README: "an integer in [1, 2048]".
std::string describe_allowed(const FieldInfo& field);
// A field's current value as TOML text ("[0.0, -9.81, 0.0]", "\"top-corners\"").
std::string format_value(const Scene& scene, const FieldInfo& field);
// Sets `field` of `to` to its value in `from` (the panel's "reset to scene value / built-in default").
void copy_field(const FieldInfo& field, const Scene& from, Scene& to);

// ---- The colliders' fields: [[colliders.shapes]] entries, each `kind` plus that kind's rows. ----
// One row of one collider: `enabled` and `friction` (every kind), then its kind's rows (shapes/*.hpp fields()).
struct ColliderField {
    std::string_view name;  // within the entry: "radius"
    std::string_view unit;
    double min, max;
    std::string_view help;
    FieldRef ref;  // into the collider
};
std::vector<ColliderField> collider_fields(Collider& collider);
// The rows of a kind as a default collider of it holds them (for listings: --list-fields, the docs); read
// them only, never write through their references.
std::vector<ColliderField> collider_fields_of_kind(std::size_t kind);
std::string describe_allowed(const ColliderField& field);
std::string format_value(const ColliderField& field);
// The kind named `name` (an index of ColliderShape), or -1. "cube" reads as "box" and "ground" as "plane" (the
// first scene-file form's names).
int find_collider_kind(std::string_view name);
// The first form's sections, [colliders.sphere], [colliders.cube], [colliders.cylinder], [colliders.ground]:
// each addresses the first collider of its kind in the list, added where the first form ordered it (sphere,
// cube, cylinder, ground), switched off, when the list has none. Returns that collider.
inline constexpr std::array<std::string_view, 4> kFirstFormSections = {"sphere", "cube", "cylinder", "ground"};
Collider& first_form_collider(ColliderSettings& colliders, std::string_view section);

// ---- Names of the enumerations, as written in files. ----
std::span<const std::string_view> pin_preset_names();   // none, top-corners, top-row, four-corners, left-edge, center
std::span<const std::string_view> clip_kind_names();    // rigid, soft
std::span<const std::string_view> wind_model_names();   // triangles, uniform
std::span<const std::string_view> solver_method_names(); // fast, textbook
std::span<const std::string_view> integrator_names();    // verlet, symplectic-euler, rk4, implicit-euler, xpbd
std::span<const std::string_view> contact_model_names(); // projection, penalty
std::span<const std::string_view> cloth_shape_names();   // rectangle, disc
std::span<const std::string_view> membrane_model_names(); // springs, triangles

// The names of an enumeration field's values, by the field's type (the loader, the field table and the
// panel treat every enumeration alike through these).
inline std::span<const std::string_view> names_of(const WindModel*) { return wind_model_names(); }
inline std::span<const std::string_view> names_of(const SolverMethod*) { return solver_method_names(); }
inline std::span<const std::string_view> names_of(const Integrator*) { return integrator_names(); }
inline std::span<const std::string_view> names_of(const ContactModel*) { return contact_model_names(); }
inline std::span<const std::string_view> names_of(const ClothShape*) { return cloth_shape_names(); }
inline std::span<const std::string_view> names_of(const MembraneModel*) { return membrane_model_names(); }

// ---- Loading and overriding. All throw SceneError; on a throw the target scene is left unchanged. ----
Scene parse_scene(std::string_view toml_text, std::string_view source_name);
Scene load_scene_file(const std::filesystem::path& path);
// A bundled scene name ("hanging") or a path to a .toml file.
Scene load_scene(std::string_view name_or_path);
// `key=value`: value is TOML ("128", "[0, -9.81, 0]", "true", "\"x\"") or a bare word ("top-row").
void apply_override(Scene& scene, std::string_view assignment);
// Every field range, and the checks that span fields (axes, pins inside the grid, grid size, penalty contact
// with a positive thickness).
void validate(const Scene& scene);
// The panel's way in, checked against the same table as the loader: clamps `field` of `scene` into its
// allowed range (each component of a vector; a non-finite value goes to the nearest bound, NaN to the
// minimum) and returns the note to show ("forces.wind = [0, 0, 1e+09] is out of range; allowed: ...; set to
// [0.0, 0.0, 10000.0]"), or nothing when the value was allowed.
std::optional<std::string> clamp_to_range(Scene& scene, const FieldInfo& field);
// The whole scene as a TOML document that parse_scene() reads back to the same Scene.
std::string to_toml(const Scene& scene);

std::filesystem::path scene_directory();  // $CLOTHSIM_SCENES, else share/clothsim/scenes (data_dirs.hpp)
std::vector<std::string> bundled_scene_names();
// Whether load_scene() reads `name_or_path` as a file (it has a '/' or ends in .toml) rather than as the name
// of a bundled scene.
bool is_scene_file(std::string_view name_or_path);

// Largest grid accepted (particles); larger grids are rejected with a message, not attempted.
inline constexpr long long kMaxParticles = 1024LL * 1024LL;
// Largest clip radius in pins (m), and the allowed radii as messages and the README state them.
inline constexpr double kMaxPinRadius = 1.0;
std::string describe_pin_radius();

// ---- Building. ----
// Pinned particle indices (row-major) for a cloth; throws SceneError for a pin outside the grid.
std::vector<std::size_t> pinned_particles(const ClothSettings& cloth, const PinSpec& pins);
// The particles of soft clips (pins.clip = "soft"), each with its clip's radius and its weight
// (1 - (d / R)^2)^2 at distance d from the clip's particle at rest: 1 there, falling smoothly to 0 at the rim.
// Point pins stay rigid (pinned_particles). Empty for rigid clips.
// A soft clip's stiffness per unit area, kappa = kClipHoldFactor E / R^2 (cloth_builder.cpp).
inline constexpr double kClipHoldFactor = 4.0;
struct ClipWeight {
    std::size_t particle;
    double weight;
    double radius;  // m
};
std::vector<ClipWeight> soft_clip_weights(const ClothSettings& cloth, const PinSpec& pins);
// The particles, springs and triangles of the grid, and the ready-to-step simulation. Throws SceneError.
MassSpring build_simulation(const Scene& scene);
// Each particle's mass (kg): a quarter of each cell around it times material.density in the material form,
// cloth.mass shared equally in the per-spring form; 0 for the slots outside the shape.
std::vector<float> particle_masses(const Scene& scene, const ShapeMask& shape);
// The fabric of `scene` (cloth.mass and springs.structural/shear/bending, or its [material]) put on the
// running cloth `sim`, built from a scene of the same grid: every particle's mass and every spring's and
// bend's k re-derived in place (MassSpring::set_masses, MassSpring::apply), positions and velocities kept.
// What the panel's fabric controls do live. Throws SceneError, changing nothing, when the grid differs, the
// form switches between bends and skip-one springs (both need a rebuild) or the material is not valid.
void apply_fabric(MassSpring& sim, const Scene& scene);

}  // namespace clothsim
