// Settings of a scene, with their defaults.
//
// These plain structs are what a scene file loads into, what `--set` overrides and what the panel edits.
// Each field's unit, valid range and one-line meaning are listed once, in src/core/scene/scene_fields.cpp
// (the field table); the comments here only repeat the unit.
#pragma once

#include "clothsim/collider.hpp"
#include "clothsim/integrator.hpp"
#include "clothsim/stretch_curve.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {

// Named sets of pinned particles (row 0 is the edge the cloth's origin lies on). Center: the middle particle
// ((rows - 1) / 2, (cols - 1) / 2), with the preset's radius a clip that stays centred at any resolution (the
// Cusick test's clamp).
enum class PinPreset { None, TopCorners, TopRow, FourCorners, LeftEdge, Center };
// The kind of clip (a pin with a radius; Pin): Rigid pins every particle within the radius; Soft holds each to
// where it is at rest by a zero-length spring whose stiffness fades to 0 at the rim (docs/MATERIAL.md,
// "Soft clips"): the load enters the cloth smoothly, and a cloth held in the plane it hangs in has a largest
// strain that converges as the grid is refined.
enum class ClipKind { Rigid, Soft };

// The time integrator (one file each in src/core/: verlet, symplectic_euler, rk4, implicit_euler, xpbd,
// projective).
// How a mesh cloth's membrane (stretch and shear) is modelled (cloth_mesh.hpp, docs/MESH_CLOTH.md).
enum class MembraneModel {
    Springs,    // van Gelder 1998's springs on the edges: the shear follows the stretch (a central-force lattice)
    Triangles,  // a constant-strain triangle per triangle (spring.hpp: Membrane): the material's own tensor
};

// The outline of the cloth on its grid.
enum class ClothShape {
    Rectangle,  // every particle of the rows x cols grid
    Disc,       // the particles inside the grid's inscribed circle (ellipse for unequal sides): a Cusick
                // specimen; the others are absent (state.hpp), with no springs, mass or triangles
};

// Which implementation advances the cloth. Both integrate the same model; see src/core/integrators/fast_solver.hpp.
enum class SolverMethod {
    Fast,      // row sweeps over the grid (Verlet's fast solver, XPBD's grid form): vectorised, threaded, stages fused
    Textbook,  // one loop over the spring list, one over the particles: the oracle the tests compare with
};

// How wind acts on the cloth.
enum class WindModel {
    Triangles,  // pressure on each triangle along its normal: an edge-on sheet feels none, a flag flutters
    Uniform,    // isotropic drag toward the air velocity, the same for every particle
};

// How the colliders act on the cloth.
enum class ContactModel {
    Projection,  // after integration, particles are projected out, with Coulomb friction and continuous
                 // collision (colliders.hpp): the default
    Penalty,     // a smooth, conservative, frictionless force k_c p^3 / thickness^2 at depth p, part of the
                 // forces the integrator sees (penalty_contact.hpp): gives the accuracy study a well-posed error
};

// The cloth's fabric in physical units, independent of the grid (material.hpp derives the per-spring values).
// Used when `enabled`; otherwise cloth.mass and springs.structural/shear/bending describe the cloth.
struct MaterialSettings {
    bool enabled = false;
    std::string preset;                    // "" or a name of material_presets(); fills the fields not set below
    float density = 0.15f;                 // kg/m^2: areal density
    glm::vec2 stretch{5000.0f, 5000.0f};   // N/m: membrane tensile stiffness along u_axis (warp), v_axis (weft)
    float shear = 100.0f;                  // N/m: in-plane shear stiffness (per radian)
    glm::vec2 bending{1e-5f, 1e-5f};       // N m: flexural rigidity per unit width, bending along u, along v
    StretchCurve stretch_curve;            // tangent stiffness over stretch past each strain; empty = linear
    // Which fields the scene sets itself (bit per MaterialField); the others follow the preset.
    unsigned explicit_fields = 0;
    bool operator==(const MaterialSettings&) const = default;
};

struct ClothSettings {
    int rows = 32;                           // particles along v_axis (count)
    int cols = 32;                           // particles along u_axis (count)
    glm::vec2 size{1.0f, 1.0f};              // m: extent along u_axis, along v_axis
    float mass = 0.5f;                       // kg: total, shared equally by all particles
    glm::vec3 origin{-0.5f, 1.5f, 0.0f};     // m: position of particle (row 0, col 0)
    glm::vec3 u_axis{1.0f, 0.0f, 0.0f};      // direction of increasing column (normalised when built)
    glm::vec3 v_axis{0.0f, -1.0f, 0.0f};     // direction of increasing row (normalised when built)
    glm::vec3 velocity{0.0f, 0.0f, 0.0f};    // m/s: initial velocity of every free particle
    ClothShape shape = ClothShape::Rectangle;
    // A triangle mesh instead of the grid (cloth_mesh.hpp): an OBJ file, found as a mesh collider's, its
    // vertices scaled by mesh_scale, turned by mesh_rotation (degrees about x, then y, then z) and moved by
    // origin. rows, cols, size, shape and v_axis then do not apply; u_axis is the warp direction.
    std::string mesh;                        // "" = the grid
    glm::vec3 mesh_rotation{0.0f, 0.0f, 0.0f};  // degrees
    float mesh_scale = 1.0f;                 // mesh units to metres
    MembraneModel membrane = MembraneModel::Springs;  // a mesh cloth's stretch and shear, with [material]
    std::shared_ptr<const TriangleMesh> mesh_data;  // read from `mesh` when the scene is loaded
    bool is_mesh() const { return !mesh.empty(); }
};

// The stiffness every spring and bend uses, by kind and axis (spring.hpp). A per-spring scene sets them
// directly; a material scene derives them from the fabric and the grid spacing (material.hpp).
struct SpringSettings {
    glm::vec2 structural{400.0f, 400.0f};  // N/m: springs along u_axis, along v_axis
    float shear = 40.0f;                   // N/m: both diagonals
    // N/m along u_axis, along v_axis: skip-one springs' k (per-spring form), or bends' k = B h_v / h_u^3
    // (material form; spring.hpp)
    glm::vec2 bending{10.0f, 10.0f};
    float damping = 0.2f;       // 1/s: velocity damping rate c in x'' = a - c x'
    float strain_limit = 0.0f;  // fraction: 0 = off; otherwise no spring ends a substep longer than (1 + it) L0
    // fraction: 0 = off; otherwise each free particle stays within (1 + it) x its rest distance of the pins it
    // hangs from (tethers.hpp)
    float tether_strain = 0.0f;
    float tear_strain = 0.0f;  // fraction: 0 = off; otherwise a spring longer than (1 + it) L0 breaks (tearing.hpp)
    // The structural springs' stretch curves along u_axis, along v_axis (stretch_curve.hpp): no knots = linear.
    // Derived from material.stretch_curve on a grid cloth.
    std::array<SpringCurve, 2> stretch_curve{};
    // A mesh cloth's material springs' curves by warp level (Spring::warp_level - 1; stretch_curve.hpp: blends of
    // both directions). Derived from material.stretch_curve on a mesh cloth.
    std::array<SpringCurve, kWarpLevels + 1> mesh_curve{};
    // A mesh cloth's membrane triangles' curves along u_axis and v_axis (Membrane; their k is the tensor's C11 and
    // C22). Derived from material.stretch_curve when cloth.membrane = "triangles".
    std::array<SpringCurve, 2> membrane_curve{};
    bool operator==(const SpringSettings&) const = default;
};

struct ForceSettings {
    glm::vec3 gravity{0.0f, -9.81f, 0.0f};  // m/s^2
    glm::vec3 wind{0.0f, 0.0f, 0.0f};       // m/s: air velocity
    WindModel wind_model = WindModel::Triangles;
    float drag = 0.6f;                      // kg/m^3: 0.5 * air density * drag coefficient
    float gust_strength = 0.0f;             // fraction of the wind speed added and removed by gusts
    float gust_frequency = 0.5f;            // Hz: main gust frequency
    float max_speed = 0.0f;                 // m/s: 0 = off; otherwise particle speeds are clamped to it
    bool operator==(const ForceSettings&) const = default;
};

// One pin: the particle (row, col) alone, or a clip that holds every particle whose rest position lies within
// `radius` of that particle's (a real cloth is held by a clip of finite size; a single pinned particle is a
// point load whose strain grows without bound as the grid is refined).
struct Pin {
    int row = 0;
    int col = 0;
    float radius = 0.0f;  // m: 0 = this particle only
    int vertex = -1;      // -1, or the vertex (from 0) instead of row and col: a mesh cloth's, or a grid's row-major
    bool operator==(const Pin&) const = default;
};

// Which particles are pinned: a named preset and/or explicit pins.
struct PinSpec {
    PinPreset preset = PinPreset::TopCorners;
    std::vector<Pin> particles;  // in addition to the preset
    float preset_radius = 0.0f;      // m: each pin of the preset is a clip of this radius (0 = point pins)
    ClipKind clip = ClipKind::Rigid;  // how every clip holds (point pins are always rigid)
    bool operator==(const PinSpec&) const = default;
};

struct ColliderSettings {
    // The objects, in the order their contacts are resolved (collider.hpp); a new scene has the ground.
    std::vector<Collider> shapes{Collider::of(PlaneCollider{})};
    float thickness = 0.005f;  // m: particles are kept this far outside every collider surface
    ContactModel contact = ContactModel::Projection;
    float contact_stiffness = 1000.0f;  // N/m: penalty contact's k_c (force k_c p^3 / thickness^2 at depth p)
    bool operator==(const ColliderSettings&) const = default;
};

// Self-collision (self_collision.hpp): the cloth's layers are kept at least the contact distance apart.
struct CollisionSettings {
    bool self = false;
    float self_thickness = 0.0f;  // m: the contact distance; it is never less than the particle spacing (0: the spacing)
    float self_friction = 0.3f;   // Coulomb friction between layers
    bool operator==(const CollisionSettings&) const = default;
};

inline constexpr int kMaxSubsteps = 10000;  // the largest integration.substeps a scene may hold

struct IntegrationSettings {
    float dt = 1.0f / 60.0f;  // s: one step (one frame of the app)
    int substeps = 34;        // integration substeps per step; each advances dt / substeps
    Integrator integrator = Integrator::Verlet;
    float tolerance = 1e-5f;  // implicit Euler, projective: the solve stops at this relative residual
    int iterations = 10;      // projective: the most local-global iterations per substep
    bool operator==(const IntegrationSettings&) const = default;
};

struct SolverSettings {
    SolverMethod method = SolverMethod::Fast;
    int threads = 0;  // worker threads for the fast solver; 0 = one per core
    bool broad_phase = true;   // test a collider only against the particle blocks whose bounds meet it
    float sleep_speed = 0.002f;  // m/s: 0 = never sleep; else the cloth sleeps once every particle is slower
    float sleep_time = 0.5f;     // s: ... for this long, with nothing driving it (docs/PERFORMANCE.md)
    bool operator==(const SolverSettings&) const = default;
};

// The settings a running simulation reads every step; all of them may change live.
struct SimulationSettings {
    SpringSettings springs;
    ForceSettings forces;
    ColliderSettings colliders;
    CollisionSettings collision;
    IntegrationSettings integration;
    SolverSettings solver;
    bool operator==(const SimulationSettings&) const = default;
};

// Everything a scene file holds. Changing cloth or pins needs a rebuild; the rest applies live.
struct Scene {
    std::string name = "untitled";
    std::string description;
    ClothSettings cloth;
    MaterialSettings material;
    // Which per-spring fields (cloth.mass, springs.structural, springs.shear, springs.bending: bit per
    // PerSpringField in material.hpp) the scene sets itself: a scene may not set them and [material] both.
    unsigned per_spring_fields = 0;
    PinSpec pins;
    SimulationSettings settings;
    // What loading it had to say besides errors, one line each (an old preset name and the fabric it loads):
    // the command line prints them, the app shows them.
    std::vector<std::string> notes;
};

}  // namespace clothsim
