// Fabric in physical units (docs/MATERIAL.md): the [material] table of a scene, its presets, and the
// per-spring values it gives on a grid.
//
// A scene describes its cloth in one of two forms:
//  - per spring: cloth.mass (total, shared equally) and springs.structural/shear/bending (each spring's k).
//    The same numbers on a finer grid are another fabric (skip-one bending springs soften with the spacing).
//  - material: areal density, membrane stretch and shear stiffness (N/m) and flexural rigidity (N m). Each
//    particle's mass and each spring's and bend's k follow from these and the grid spacing, so the cloth is
//    the same fabric at every resolution. Bending acts through bends (spring.hpp), not skip-one springs.
#pragma once

#include "clothsim/settings.hpp"

#include <glm/vec2.hpp>

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace clothsim {

struct Scene;

// Bits of MaterialSettings::explicit_fields.
enum MaterialField : unsigned {
    kMaterialDensity = 1u,
    kMaterialStretch = 2u,
    kMaterialShear = 4u,
    kMaterialBending = 8u,
    kMaterialStretchCurve = 16u,
};
// Bits of Scene::per_spring_fields.
enum PerSpringField : unsigned {
    kClothMass = 1u,
    kSpringsStructural = 2u,
    kSpringsShear = 4u,
    kSpringsBending = 8u,
};

// A measured fabric (sources in docs/MATERIAL.md).
struct MaterialPreset {
    std::string_view name;
    float density;          // kg/m^2
    glm::vec2 stretch;      // N/m: warp (u_axis), weft (v_axis)
    float shear;            // N/m
    glm::vec2 bending;      // N m: warp, weft
    std::string_view note;  // the fabric measured and where, one line
    // Wang et al. 2011's stretching rows for a fabric they measured in full (its stretch curve); nullptr for a
    // linear preset.
    const WangStretching* stretching = nullptr;
};
// A preset's stretch curve: Wang et al.'s fitted model sampled (stretch_curve.hpp); empty (linear) otherwise.
StretchCurve preset_stretch_curve(const MaterialPreset& preset);
std::span<const MaterialPreset> material_presets();
// By name, or by a name it had (material_preset_alias_note).
const MaterialPreset* find_material_preset(std::string_view name);
// For a name a preset had ("silk"): the note that says which preset it loads and why; nothing otherwise. A
// scene given an old name holds the preset's own name and this note in Scene::notes.
std::optional<std::string> material_preset_alias_note(std::string_view name);

// Grid spacing (m): along u_axis (between columns) and along v_axis (between rows).
glm::dvec2 grid_spacing(const ClothSettings& cloth);

// What a material gives on a grid: every spring's and bend's k, and the membrane it makes.
//
// Springs are assembled cell by cell: each cell of h_u x h_v carries its share of the membrane energy, so a
// structural spring on the cloth's edge (one cell) gets half the weight of an inner one (two cells), and
// each particle carries a quarter of each cell around it. The cell's stiffness tensor is then
//   C11 = a_u + G (h_u/h_v)^2,  C22 = a_v + G (h_v/h_u)^2,  C12 = C66 = G,
// with a_u = k_u h_u / h_v from the structural springs and the diagonals' k_d = G (h_u^2 + h_v^2) / (2 h_u h_v)
// giving shear G and, by the Cauchy relation of a central-force lattice, C12 = G. Under uniaxial tension
// along u, with the other direction free, the force per width per strain is C11 - C12^2 / C22: a_u and a_v
// are chosen so that it equals material.stretch along each axis (docs/MATERIAL.md has the derivation; the
// Poisson ratio C12 / C22 follows and is reported).
struct SpringConstants {
    glm::dvec2 structural;  // N/m: k of an inner spring along u, along v
    double shear = 0.0;     // N/m: k of a diagonal spring
    glm::dvec2 bending;     // N/m: k of an inner bend along u (B_u h_v / h_u^3), along v
    double poisson_uv = 0.0;  // contraction along v per stretch along u, uniaxial
    double poisson_vu = 0.0;
    double total_mass = 0.0;  // kg: density x the area of the shape's cells
    // Empty, or why the membrane is stiffer than asked along an axis (long thin cells: the diagonals alone
    // exceed the stretch there; the structural springs of that axis are 0).
    std::string note;
};
// Throws SceneError when the grid has a single row or column (no cells).
SpringConstants spring_constants(const ClothSettings& cloth, const MaterialSettings& material);

// Bookkeeping after one field of `scene` was set (by a file, --set or the panel): a material field puts the
// scene in the material form and, unless it is the preset, marks itself explicit; the preset fills the
// material fields the scene does not set; a per-spring field is recorded (validate() refuses both forms).
void note_field_set(Scene& scene, std::string_view field);
// The springs' k and cloth.mass from the material, when the scene uses one; nothing otherwise. Called after
// every change (load, --set, panel), so settings.springs is always what the solvers use.
void derive_springs(Scene& scene);
// "" when the scene is consistent; else what clashes, naming the fields (validate() throws it).
std::string material_clash(const Scene& scene);
// Whether the scene writes `field` (to_toml): in the material form, the per-spring fields are derived and
// the material fields only the preset and the explicit ones; in the per-spring form, no material field.
bool field_is_written(const Scene& scene, std::string_view field);

}  // namespace clothsim
