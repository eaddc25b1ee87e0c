// The one place that says each scene field's unit, valid range and meaning. The loader, --set, validate(),
// to_toml(), the README's field list and the panel's tooltips all read this table.
#include "clothsim/scene.hpp"

#include "scene/cloth_shape.hpp"
#include "clothsim/cloth_mesh.hpp"
#include "clothsim/collider_motion.hpp"
#include "clothsim/material.hpp"
#include "clothsim/overloaded.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <charconv>
#include <cstdio>
#include <sstream>
#include <type_traits>

namespace clothsim {
namespace {

constexpr double kBig = 1e4;

// clang-format off
const std::array kFields = {
    FieldInfo{"name", "", 0, 0, "scene name", [](Scene& s) -> FieldRef { return &s.name; }},
    FieldInfo{"description", "", 0, 0, "one-line description", [](Scene& s) -> FieldRef { return &s.description; }},

    FieldInfo{"cloth.rows", "", 1, 2048, "particles along v_axis (rows x cols <= 1048576)", [](Scene& s) -> FieldRef { return &s.cloth.rows; }},
    FieldInfo{"cloth.cols", "", 1, 2048, "particles along u_axis", [](Scene& s) -> FieldRef { return &s.cloth.cols; }},
    FieldInfo{"cloth.size", "m", 1e-3, 1e3, "[width along u_axis, height along v_axis]; one number for a square", [](Scene& s) -> FieldRef { return &s.cloth.size; }},
    FieldInfo{"cloth.mass", "kg", 1e-6, 1e6, "total mass, shared equally by all particles (derived from material.density when the scene has [material])", [](Scene& s) -> FieldRef { return &s.cloth.mass; }},
    FieldInfo{"cloth.origin", "m", -kBig, kBig, "position of particle (row 0, col 0); for a mesh cloth, where the mesh's origin goes", [](Scene& s) -> FieldRef { return &s.cloth.origin; }},
    FieldInfo{"cloth.u_axis", "", -1e3, 1e3, "direction of increasing column (normalised; not parallel to v_axis)", [](Scene& s) -> FieldRef { return &s.cloth.u_axis; }},
    FieldInfo{"cloth.v_axis", "", -1e3, 1e3, "direction of increasing row (normalised)", [](Scene& s) -> FieldRef { return &s.cloth.v_axis; }},
    FieldInfo{"cloth.shape", "", 0, 0, "rectangle: the whole grid; disc: the particles inside the grid's inscribed circle (a Cusick drape specimen)", [](Scene& s) -> FieldRef { return &s.cloth.shape; }},
    FieldInfo{"cloth.mesh", "", 0, 0, "a Wavefront OBJ file whose triangles are the cloth (beside the scene file, else a bundled mesh); \"\" = the rows x cols grid. Its vertices are the particles, pinned by index: pins = [{ vertex = 0 }]", [](Scene& s) -> FieldRef { return &s.cloth.mesh; }},
    FieldInfo{"cloth.mesh_rotation", "degrees", -360, 360, "a mesh cloth turned about x, then y, then z (then moved by cloth.origin)", [](Scene& s) -> FieldRef { return &s.cloth.mesh_rotation; }},
    FieldInfo{"cloth.mesh_scale", "", 1e-6, 1e4, "a mesh cloth's units to metres", [](Scene& s) -> FieldRef { return &s.cloth.mesh_scale; }},
    FieldInfo{"cloth.membrane", "", 0, 0, "a mesh cloth's stretch and shear with [material]: springs (van Gelder's on the edges; shear follows stretch) or triangles (a constant-strain triangle each: the material's stretch and shear exactly, on any triangulation)", [](Scene& s) -> FieldRef { return &s.cloth.membrane; }},
    FieldInfo{"cloth.velocity", "m/s", -1e3, 1e3, "initial velocity of every free particle", [](Scene& s) -> FieldRef { return &s.cloth.velocity; }},

    FieldInfo{"material.enabled", "", 0, 0, "whether [material] describes the cloth (any other material field turns it on); false returns to the per-spring form, keeping the mass and spring constants derived on this grid", [](Scene& s) -> FieldRef { return &s.material.enabled; }},
    FieldInfo{"material.preset", "", 0, 0, "a measured fabric (docs/MATERIAL.md, \"Presets\": the Matsudaira et al. fabrics cotton-broadcloth, polyester-tropical and polyester-faille, denim, and Wang et al.'s fabrics, as gray-interlock or 11oz-black-denim; the old names cotton, polyester, silk and wool-jersey load with a note) that fills the material fields this scene does not set", [](Scene& s) -> FieldRef { return &s.material.preset; }},
    FieldInfo{"material.density", "kg/m^2", 1e-3, 100, "areal density (mass per area)", [](Scene& s) -> FieldRef { return &s.material.density; }},
    FieldInfo{"material.stretch", "N/m", 1e-2, 1e7, "membrane tensile stiffness (force per width per strain): one number, or [warp along u_axis, weft along v_axis]", [](Scene& s) -> FieldRef { return &s.material.stretch; }},
    FieldInfo{"material.shear", "N/m", 0, 1e7, "in-plane shear stiffness (force per width per radian of shear)", [](Scene& s) -> FieldRef { return &s.material.shear; }},
    FieldInfo{"material.stretch_curve", "", 0, 1e4, "nonlinear stretch: { u = [[strain, factor], ...], v = [...] }, from each strain on (increasing, in (0, 1]) the tensile tangent stiffness is factor x material.stretch; {} = linear (Wang et al. presets carry their measured curves; on a mesh cloth at most 8 distinct strains in u and v together)", [](Scene& s) -> FieldRef { return &s.material.stretch_curve; }},
    FieldInfo{"material.bending", "N m", 0, 10, "flexural rigidity per unit width: one number, or [bending along u, along v]", [](Scene& s) -> FieldRef { return &s.material.bending; }},

    FieldInfo{"springs.structural", "N/m", 0, 1e9, "stiffness of each horizontal and vertical neighbour spring: one number, or [along u_axis, along v_axis] (derived from [material] when the scene has one)", [](Scene& s) -> FieldRef { return &s.settings.springs.structural; }},
    FieldInfo{"springs.shear", "N/m", 0, 1e9, "stiffness of each diagonal spring (derived from [material] when the scene has one)", [](Scene& s) -> FieldRef { return &s.settings.springs.shear; }},
    FieldInfo{"springs.bending", "N/m", 0, 1e9, "stiffness of each spring two apart along rows and columns: one number, or [along u, along v] (with [material]: each bend's k = B h_v / h_u^3, derived)", [](Scene& s) -> FieldRef { return &s.settings.springs.bending; }},
    FieldInfo{"springs.damping", "1/s", 0, 1e4, "velocity damping rate c in x'' = a - c x' (independent of dt)", [](Scene& s) -> FieldRef { return &s.settings.springs.damping; }},
    FieldInfo{"springs.tether_strain", "", 0, 10, "0 = off; else tethers (long-range attachments, Kim et al. 2012): each free particle stays within (1 + this) x its rest distance of the pins it hangs from (0.01 = 1%)", [](Scene& s) -> FieldRef { return &s.settings.springs.tether_strain; }},
    FieldInfo{"springs.tear_strain", "", 0, 10, "0 = off; else a spring stretched beyond (1 + this) x its rest length breaks, checked once per step (0.5 = 50%)", [](Scene& s) -> FieldRef { return &s.settings.springs.tear_strain; }},
    FieldInfo{"springs.strain_limit", "", 0, 10, "0 = off; else Provot's limit: no spring ends a substep longer than (1 + this) x its rest length (0.1 = 10%)", [](Scene& s) -> FieldRef { return &s.settings.springs.strain_limit; }},

    FieldInfo{"forces.gravity", "m/s^2", -1e5, 1e5, "gravitational acceleration", [](Scene& s) -> FieldRef { return &s.settings.forces.gravity; }},
    FieldInfo{"forces.wind", "m/s", -kBig, kBig, "air velocity", [](Scene& s) -> FieldRef { return &s.settings.forces.wind; }},
    FieldInfo{"forces.wind_model", "", 0, 0, "triangles: pressure on each triangle's normal; uniform: the same drag on every particle", [](Scene& s) -> FieldRef { return &s.settings.forces.wind_model; }},
    FieldInfo{"forces.drag", "kg/m^3", 0, 1e3, "0.5 x air density x drag coefficient", [](Scene& s) -> FieldRef { return &s.settings.forces.drag; }},
    FieldInfo{"forces.gust_strength", "", 0, 1, "fraction of the wind speed gusts add and remove", [](Scene& s) -> FieldRef { return &s.settings.forces.gust_strength; }},
    FieldInfo{"forces.gust_frequency", "Hz", 0, 100, "main gust frequency", [](Scene& s) -> FieldRef { return &s.settings.forces.gust_frequency; }},
    FieldInfo{"forces.max_speed", "m/s", 0, 1e4, "0 = off; else every particle's speed is clamped to this", [](Scene& s) -> FieldRef { return &s.settings.forces.max_speed; }},

    FieldInfo{"pins", "", 0, 0, "a preset name, a list of pins, or { preset = NAME, radius = R, particles = [...] }; a pin is [row, col] or a clip { particle = [row, col], radius = R } holding every particle within R m of it at rest, or { vertex = i } (with a radius: a clip), a mesh cloth's vertex or a grid's row-major particle; the table's radius makes each preset pin a clip; clip = \"soft\" holds a clip's particles by springs that fade to 0 at its rim instead of pinning them (the load enters the cloth smoothly)", [](Scene& s) -> FieldRef { return &s.pins; }},

    FieldInfo{"colliders.thickness", "m", 0, 1, "distance particles keep from every collider surface", [](Scene& s) -> FieldRef { return &s.settings.colliders.thickness; }},
    FieldInfo{"colliders.contact", "", 0, 0, "projection: particles are moved out of the thickness shell after each substep, with Coulomb friction and continuous collision; penalty: a smooth force contact_stiffness x depth^3 / thickness^2 pushes them out (frictionless: friction is ignored; no continuous collision; thickness > 0)", [](Scene& s) -> FieldRef { return &s.settings.colliders.contact; }},
    FieldInfo{"colliders.contact_stiffness", "N/m", 1, 1e9, "penalty contact's k_c: the push at depth = thickness is k_c x thickness (unused by projection)", [](Scene& s) -> FieldRef { return &s.settings.colliders.contact_stiffness; }},

    FieldInfo{"collision.self", "", 0, 0, "keep the cloth's layers apart: particles that share no spring stay collision.self_thickness apart (self_collision.hpp)", [](Scene& s) -> FieldRef { return &s.settings.collision.self; }},
    FieldInfo{"collision.self_thickness", "m", 0, 1, "distance kept between layers; never less than the particle spacing (0 = the spacing), which keeps layers from passing between particles", [](Scene& s) -> FieldRef { return &s.settings.collision.self_thickness; }},
    FieldInfo{"collision.self_friction", "", 0, 10, "Coulomb friction between layers in contact", [](Scene& s) -> FieldRef { return &s.settings.collision.self_friction; }},

    FieldInfo{"integration.dt", "s", 1e-7, 1, "one step (an app frame); each substep advances dt / substeps", [](Scene& s) -> FieldRef { return &s.settings.integration.dt; }},
    FieldInfo{"integration.substeps", "", 1, kMaxSubsteps, "integration substeps per step", [](Scene& s) -> FieldRef { return &s.settings.integration.substeps; }},
    FieldInfo{"integration.integrator", "", 0, 0, "time integrator (orders: verlet 2, symplectic-euler 1, rk4 4, implicit-euler 1, projective 2 (BDF2 by quasi-Newton on a prefactorised matrix; stable at any step); xpbd tends to the spring model as substeps grow)", [](Scene& s) -> FieldRef { return &s.settings.integration.integrator; }},
    FieldInfo{"integration.tolerance", "", 1e-12, 0.1, "implicit-euler: conjugate-gradient residual relative to the right-hand side; projective: the step's force imbalance |grad g| relative to its start or to the loads, whichever is larger", [](Scene& s) -> FieldRef { return &s.settings.integration.tolerance; }},
    FieldInfo{"integration.iterations", "", 1, 1000, "projective: the most quasi-Newton iterations per substep (each one solve with the prefactorised matrix)", [](Scene& s) -> FieldRef { return &s.settings.integration.iterations; }},

    FieldInfo{"solver.method", "", 0, 0, "fast: vectorised multi-threaded row sweeps; textbook: spring-list loop (the test oracle)", [](Scene& s) -> FieldRef { return &s.settings.solver.method; }},
    FieldInfo{"solver.threads", "", 0, 64, "threads of the fast path (fast solver, a mesh cloth's element gather, grid and coloured XPBD, collision tests); 0 = one per core, or one while that is faster; results are identical for any count", [](Scene& s) -> FieldRef { return &s.settings.solver.threads; }},
    FieldInfo{"solver.broad_phase", "", 0, 0, "test a collider only on particle blocks whose bounds meet it (results are identical; false tests every particle)", [](Scene& s) -> FieldRef { return &s.settings.solver.broad_phase; }},
    FieldInfo{"solver.sleep_speed", "m/s", 0, 10, "0 = never sleep; else the cloth sleeps once every free particle stays slower than this for sleep_time with still air", [](Scene& s) -> FieldRef { return &s.settings.solver.sleep_speed; }},
    FieldInfo{"solver.sleep_time", "s", 0, 1e4, "how long the cloth must stay under sleep_speed before it sleeps", [](Scene& s) -> FieldRef { return &s.settings.solver.sleep_time; }},
};
// clang-format on

constexpr std::array<std::string_view, 6> kPinPresetNames = {"none",         "top-corners", "top-row", "four-corners",
                                                             "left-edge",    "center"};
constexpr std::array<std::string_view, 2> kClipKindNames = {"rigid", "soft"};
constexpr std::array<std::string_view, 2> kWindModelNames = {"triangles", "uniform"};
constexpr std::array<std::string_view, 2> kSolverMethodNames = {"fast", "textbook"};
// The integrators' names, from their table (integrator.hpp).
constexpr std::array<std::string_view, kIntegrators.size()> kIntegratorNames = [] {
    std::array<std::string_view, kIntegrators.size()> names{};
    for (std::size_t i = 0; i < kIntegrators.size(); ++i) names[i] = kIntegrators[i].name;
    return names;
}();
constexpr std::array<std::string_view, 2> kContactModelNames = {"projection", "penalty"};
constexpr std::array<std::string_view, 2> kClothShapeNames = {"rectangle", "disc"};
constexpr std::array<std::string_view, 2> kMembraneModelNames = {"springs", "triangles"};

// Shortest text that reads back to the same float (std::to_chars), so 0.2f prints as 0.2, not 0.200000003.
std::string number(double v) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, static_cast<float>(v));
    std::string s(buffer, result.ptr);
    // Keep TOML floats floats: "1" would read back as an integer.
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
    return s;
}

// Appends instead of operator+ chains: GCC 12 warns falsely (-Wrestrict, GCC bug 105329) on "literal" + string.
template <class... Parts>
std::string cat(const Parts&... parts) {
    std::string s;
    (s.append(std::string_view(parts)), ...);
    return s;
}


}  // namespace

std::span<const FieldInfo> scene_fields() { return kFields; }

const FieldInfo* find_field(std::string_view name) {
    for (const FieldInfo& f : kFields) {
        if (f.name == name) return &f;
    }
    return nullptr;
}

std::span<const std::string_view> pin_preset_names() { return kPinPresetNames; }
std::span<const std::string_view> clip_kind_names() { return kClipKindNames; }
std::span<const std::string_view> wind_model_names() { return kWindModelNames; }
std::span<const std::string_view> solver_method_names() { return kSolverMethodNames; }
std::span<const std::string_view> integrator_names() { return kIntegratorNames; }
std::span<const std::string_view> contact_model_names() { return kContactModelNames; }
std::span<const std::string_view> cloth_shape_names() { return kClothShapeNames; }
std::span<const std::string_view> membrane_model_names() { return kMembraneModelNames; }

std::string describe_pin_radius() { return cat("a number in [0.0, ", number(kMaxPinRadius), "] m"); }

namespace {

// A field's allowed values from its unit, range and type (the reference's alternative).
std::string describe_allowed_as(std::string_view unit_name, double min, double max, FieldRef sample) {
    const std::string unit = unit_name.empty() ? "" : cat(" ", unit_name);
    const std::string bounds = cat("[", number(min), ", ", number(max), "]");
    auto join = [](std::span<const std::string_view> names) {
        std::string s;
        for (std::size_t i = 0; i < names.size(); ++i) s += cat(i ? ", " : "", names[i]);
        return s;
    };
    return std::visit(
        Overloaded{
            [&](int*) { return cat("an integer in [", std::to_string(int(min)), ", ", std::to_string(int(max)), "]"); },
            [&](float*) { return cat("a number in ", bounds, unit); },
            [&](bool*) { return std::string("true or false"); },
            [&](glm::vec2*) { return cat("one number or [x, y], each in ", bounds, unit); },
            [&](glm::vec3*) { return cat("[x, y, z], each in ", bounds, unit); },
            [&](std::string*) { return std::string("a string"); },
            [&](PinSpec*) {
                return cat("one of ", join(kPinPresetNames),
                           ", a list of [row, col], { particle = [row, col], radius = R } or { vertex = i, radius = R }, or a table with preset, "
                           "radius, particles and clip (rigid or soft); R: ",
                           describe_pin_radius(), " (0 = a point pin)");
            },
            [&](StretchCurve*) {
                return std::string("{ u = [[strain, factor], ...], v = [...] } with at most 8 samples a direction, "
                                   "strains increasing in (0, 1], factors in (0, 1e4]; {} = linear");
            },
            [&]<class Enum>(Enum* v) requires std::is_enum_v<Enum> { return "one of " + join(names_of(v)); },
        },
        sample);
}

}  // namespace

std::string describe_allowed(const FieldInfo& field) {
    Scene scratch;
    return describe_allowed_as(field.unit, field.min, field.max, field.ref(scratch));
}

ConstFieldRef FieldInfo::read(const Scene& scene) const {
    // The table's accessors take a mutable scene (the panel and the loader write through them); reading
    // through one changes nothing, and what comes back is const.
    return std::visit([](auto* field) -> ConstFieldRef { return field; }, ref(const_cast<Scene&>(scene)));
}

void copy_field(const FieldInfo& field, const Scene& from, Scene& to) {
    // Both variants hold the same alternative (one accessor). The types are named as template parameters: a
    // test of decltype(dst) against decltype(src) inside the nested generic lambdas built, with GCC 12, into a
    // copy that never ran (the panel's reset did nothing; test_scene_file.cpp checks every field).
    std::visit([&]<class T>(T* dst) {
        std::visit([&]<class U>(const U* src) {
            if constexpr (std::is_same_v<T, U>) *dst = *src;
        }, field.read(from));
    }, field.ref(to));
}

namespace {

// A value as TOML text.
std::string format_ref(ConstFieldRef value) {
    // A TOML basic string: quotes, backslashes and control characters escaped (TOML 1.0, "String").
    auto quoted = [](std::string_view text) {
        std::string out = "\"";
        for (const char c : text) {
            const auto u = static_cast<unsigned char>(c);
            if (c == '"' || c == '\\') {
                out += '\\';
                out += c;
            } else if (u < 0x20 || u == 0x7f) {
                char escape[8];
                std::snprintf(escape, sizeof escape, "\\u%04X", u);
                out += escape;
            } else {
                out += c;
            }
        }
        return out + "\"";
    };
    return std::visit(
        Overloaded{
            [&](const int* v) { return std::to_string(*v); },
            [&](const float* v) { return number(*v); },
            [&](const bool* v) { return std::string(*v ? "true" : "false"); },
            [&](const glm::vec2* v) { return v->x == v->y ? number(v->x) : cat("[", number(v->x), ", ", number(v->y), "]"); },
            [&](const glm::vec3* v) { return cat("[", number(v->x), ", ", number(v->y), ", ", number(v->z), "]"); },
            [&](const std::string* v) { return quoted(*v); },
            [&](const PinSpec* v) {
                std::string preset = quoted(kPinPresetNames[static_cast<int>(v->preset)]);
                if (v->particles.empty() && v->preset_radius == 0.0f && v->clip == ClipKind::Rigid) return preset;
                std::string out = cat("{ preset = ", preset);
                if (v->preset_radius != 0.0f) out += cat(", radius = ", number(v->preset_radius));
                if (v->clip != ClipKind::Rigid) out += cat(", clip = ", quoted(clip_kind_names()[static_cast<int>(v->clip)]));
                if (v->particles.empty()) return cat(out, " }");
                std::string list;
                for (const Pin& p : v->particles) {
                    const std::string cell = cat("[", std::to_string(p.row), ", ", std::to_string(p.col), "]");
                    std::string pin =
                        p.radius == 0.0f ? cell : cat("{ particle = ", cell, ", radius = ", number(p.radius), " }");
                    if (p.vertex >= 0) {
                        pin = cat("{ vertex = ", std::to_string(p.vertex),
                                  p.radius == 0.0f ? std::string() : cat(", radius = ", number(p.radius)), " }");
                    }
                    list += cat(list.empty() ? "" : ", ", pin);
                }
                return cat(out, ", particles = [", list, "] }");
            },
            [&](const StretchCurve* v) {
                auto list = [](const std::vector<StretchSample>& samples) {
                    std::string out;
                    for (const StretchSample& s : samples) out += cat(out.empty() ? "" : ", ", "[", number(s.strain), ", ", number(s.factor), "]");
                    return cat("[", out, "]");
                };
                if (v->empty()) return std::string("{}");
                return cat("{ u = ", list(v->u), ", v = ", list(v->v), " }");
            },
            [&]<class Enum>(const Enum* v) requires std::is_enum_v<Enum> { return quoted(names_of(v)[static_cast<int>(*v)]); },
        },
        value);
}

}  // namespace

std::string format_value(const Scene& scene, const FieldInfo& field) { return format_ref(field.read(scene)); }


void validate(const Scene& scene) {
    for (const FieldInfo& f : kFields) {
        // A field the scene does not hold itself (a per-spring value derived from [material], a preset's value)
        // is not the user's to range-check: cloth.size = 0.001 derives a mass below cloth.mass's minimum.
        if (!field_is_written(scene, f.name)) continue;
        auto fail = [&] {
            throw SceneError(std::string(f.name) + " = " + format_value(scene, f) + " is out of range; allowed: " +
                             describe_allowed(f));
        };
        auto in_range = [&](double v) { return std::isfinite(v) && v >= f.min && v <= f.max; };
        // Stored floats are compared with the bounds rounded to float: 1e-6 loads as 9.99999997e-7f.
        auto in_float_range = [&](float v) {
            return std::isfinite(v) && v >= static_cast<float>(f.min) && v <= static_cast<float>(f.max);
        };
        std::visit(Overloaded{
                       [&](const int* v) { if (!in_range(*v)) fail(); },
                       [&](const float* v) { if (!in_float_range(*v)) fail(); },
                       [&](const glm::vec2* v) { if (!in_float_range(v->x) || !in_float_range(v->y)) fail(); },
                       [&](const glm::vec3* v) { if (!in_float_range(v->x) || !in_float_range(v->y) || !in_float_range(v->z)) fail(); },
                       [&](const auto*) {},
                   },
                   f.read(scene));
    }
    const ClothSettings& c = scene.cloth;
    if (static_cast<long long>(c.rows) * c.cols > kMaxParticles) {
        throw SceneError("cloth.rows x cloth.cols = " + std::to_string(static_cast<long long>(c.rows) * c.cols) +
                         " particles is too many; allowed: at most " + std::to_string(kMaxParticles));
    }
    const float lu = glm::length(c.u_axis), lv = glm::length(c.v_axis);
    if (!(lu > 1e-6f)) throw SceneError("cloth.u_axis = " + format_value(scene, *find_field("cloth.u_axis")) + " has no direction; allowed: a non-zero vector");
    if (!(lv > 1e-6f)) throw SceneError("cloth.v_axis = " + format_value(scene, *find_field("cloth.v_axis")) + " has no direction; allowed: a non-zero vector");
    if (glm::length(glm::cross(c.u_axis / lu, c.v_axis / lv)) < 1e-3f) {
        throw SceneError("cloth.u_axis and cloth.v_axis are parallel; allowed: two non-parallel directions");
    }
    if (!c.is_mesh() && c.shape == ClothShape::Disc && shape_mask(c).cell_count == 0) {
        throw SceneError("cloth.shape = \"disc\" keeps no whole cell of the " + std::to_string(c.rows) + " x " +
                         std::to_string(c.cols) + " grid; allowed: a grid whose inscribed circle holds a cell (5 x 5 "
                         "particles or more)");
    }
    if (const std::string clash = material_clash(scene); !clash.empty()) throw SceneError(clash);
    if (scene.material.enabled && !c.is_mesh()) spring_constants(scene.cloth, scene.material);  // throws what it cannot derive
    if (c.membrane == MembraneModel::Triangles && c.is_mesh() && !scene.material.enabled) {
        throw SceneError("cloth.membrane = \"triangles\" takes the membrane's tensor from [material]; allowed without "
                         "[material] (per-spring values): \"springs\"");
    }
    if (scene.material.enabled) {
        const StretchCurve& curve = scene.material.stretch_curve;
        for (const auto& [axis, samples] : {std::pair{"u", &curve.u}, std::pair{"v", &curve.v}}) {
            if (const std::string problem = stretch_samples_problem(*samples); !problem.empty()) {
                throw SceneError(cat("material.stretch_curve.", axis, ": ", problem));
            }
        }
        const bool blended = c.is_mesh() && c.membrane == MembraneModel::Springs;  // the edge springs' blends
        if (const std::string problem = blended ? mesh_curve_problem(curve) : ""; !problem.empty()) {
            throw SceneError("material.stretch_curve: " + problem + " (docs/MATERIAL.md, \"Nonlinear stretch\")");
        }
    }
    const ColliderSettings& colliders = scene.settings.colliders;
    if (colliders.contact == ContactModel::Penalty && !(colliders.thickness > 0.0f)) {
        throw SceneError("colliders.thickness = " + format_value(scene, *find_field("colliders.thickness")) +
                         " leaves penalty contact no shell to push in; allowed with colliders.contact = \"penalty\": "
                         "a thickness in (0.0, 1.0] m");
    }
    for (std::size_t i = 0; i < colliders.shapes.size(); ++i) {
        Collider collider = colliders.shapes[i];
        for (const ColliderField& f : collider_fields(collider)) {
            auto in_range = [&](float v) {
                return std::isfinite(v) && v >= static_cast<float>(f.min) && v <= static_cast<float>(f.max);
            };
            const bool ok = std::visit(Overloaded{
                                           [&](const float* v) { return in_range(*v); },
                                           [&](const glm::vec3* v) { return in_range(v->x) && in_range(v->y) && in_range(v->z); },
                                           [&](const auto*) { return true; },
                                       },
                                       f.ref);
            if (!ok) {
                throw SceneError(cat("colliders.shapes[", std::to_string(i), "] (", kind_name(collider), "): ", f.name,
                                     " = ", format_value(f), " is out of range; allowed: ", describe_allowed(f)));
            }
        }
        if (const auto problem = spin_problem(collider)) {
            throw SceneError(cat("colliders.shapes[", std::to_string(i), "] (", kind_name(collider), "): spin = ",
                                 format_ref(ConstFieldRef(&collider.motion.spin)), ": ", *problem));
        }
        if (const auto* mesh = std::get_if<MeshCollider>(&collider.shape); mesh && !mesh->mesh) {
            throw SceneError(cat("colliders.shapes[", std::to_string(i), "] (mesh): file = \"", mesh->file,
                                 "\" holds no mesh; allowed: a Wavefront OBJ file that loads"));
        }
    }
    auto check_radius = [&](float radius, const std::string& what) {
        if (!(radius >= 0.0f && radius <= static_cast<float>(kMaxPinRadius))) {
            throw SceneError(
                cat("pins: ", what, " = ", number(radius), " is out of range; allowed: ", describe_pin_radius()));
        }
    };
    check_radius(scene.pins.preset_radius, "radius");
    // A soft clip is a pin with a radius (ClipKind): "soft" with none would hold nothing softly, silently.
    const bool any_clip = (scene.pins.preset != PinPreset::None && scene.pins.preset_radius > 0.0f) ||
                          std::any_of(scene.pins.particles.begin(), scene.pins.particles.end(),
                                      [](const Pin& pin) { return pin.radius > 0.0f; });
    if (scene.pins.clip == ClipKind::Soft && !any_clip) {
        throw SceneError("pins: clip = \"soft\" has no clip to hold softly: no pin has a radius; allowed with "
                         "clip = \"soft\": pins.radius > 0 or a pin { particle = [row, col], radius = R } with R > 0");
    }
    if (c.is_mesh()) {
        validate_mesh_cloth(scene);
        for (const Pin& pin : scene.pins.particles) {
            check_radius(pin.radius, cat("the radius of the clip at vertex ", std::to_string(pin.vertex)));
        }
        return;
    }
    for (const Pin& pin : scene.pins.particles) {
        const int r = pin.row, col = pin.col;
        check_radius(pin.radius, cat("the radius of the clip at [", std::to_string(r), ", ", std::to_string(col), "]"));
        if (pin.vertex >= 0) {  // a grid's vertices are its particles, row-major
            if (static_cast<long long>(pin.vertex) >= static_cast<long long>(c.rows) * c.cols) {
                throw SceneError("pins: vertex " + std::to_string(pin.vertex) + " is not a particle of the " +
                                 std::to_string(c.rows) + " x " + std::to_string(c.cols) + " grid; allowed: a vertex in [0, " +
                                 std::to_string(static_cast<long long>(c.rows) * c.cols - 1) + "] (row-major)");
            }
            continue;
        }
        if (r < 0 || r >= c.rows || col < 0 || col >= c.cols) {
            throw SceneError("pins: particle [" + std::to_string(r) + ", " + std::to_string(col) +
                             "] is outside the " + std::to_string(c.rows) + " x " + std::to_string(c.cols) +
                             " grid; allowed: row in [0, " + std::to_string(c.rows - 1) + "], col in [0, " +
                             std::to_string(c.cols - 1) + "]");
        }
    }
}

std::optional<std::string> clamp_to_range(Scene& scene, const FieldInfo& f) {
    const std::string before = format_value(scene, f);
    bool clamped = false;
    // The bounds as the loader compares them (rounded to float for stored floats).
    auto clamp = [&](auto& v) {
        using T = std::remove_reference_t<decltype(v)>;
        const T lo = static_cast<T>(f.min), hi = static_cast<T>(f.max);
        if (v >= lo && v <= hi) return;  // false for NaN
        v = v > hi ? hi : lo;
        clamped = true;
    };
    std::visit(Overloaded{
                   [&](int* v) { clamp(*v); },
                   [&](float* v) { clamp(*v); },
                   [&](glm::vec2* v) { clamp(v->x), clamp(v->y); },
                   [&](glm::vec3* v) { clamp(v->x), clamp(v->y), clamp(v->z); },
                   [&](auto*) {},
               },
               f.ref(scene));
    if (!clamped) return std::nullopt;
    return std::string(f.name) + " = " + before + " is out of range; allowed: " + describe_allowed(f) + "; set to " +
           format_value(scene, f);
}

std::vector<ColliderField> collider_fields(Collider& collider) {
    std::vector<ColliderField> rows = {
        {"enabled", "", 0, 0, "collide with it (false keeps it in the scene, without contact)", &collider.enabled},
        {"friction", "", 0, 10, "Coulomb friction coefficient (0 = frictionless)", &collider.friction},
        {"velocity", "m/s", -kMaxColliderSpeed, kMaxColliderSpeed, "moves it at this velocity from its pose at time 0 (a kinematic collider: the cloth does not push it)", &collider.motion.velocity},
        {"spin", "degrees/s", -kMaxColliderSpin, kMaxColliderSpin, "turns it about its centre at these rates of its angles about x, y, z (a sphere, a cylinder about y and a plane about y: only their surface moves; a box: none)", &collider.motion.spin},
    };
    std::visit([&]<class Shape>(Shape& shape) {
        for (const ShapeField<Shape>& f : Shape::fields()) {
            rows.push_back({f.name, f.unit, f.min, f.max, f.help,
                            std::visit([](auto* v) -> FieldRef { return v; }, f.ref(shape))});
        }
    }, collider.shape);
    return rows;
}

std::vector<ColliderField> collider_fields_of_kind(std::size_t kind) {
    // One default collider per kind, made once and never written: the rows' references stay valid while the
    // program runs, whichever kind is asked for next (a shared scratch rewritten per call would leave an
    // earlier call's references pointing into a shape of another kind).
    static const std::array<Collider, kColliderKindCount> defaults = [] {
        std::array<Collider, kColliderKindCount> all;
        for (std::size_t k = 0; k < kColliderKindCount; ++k) all[k] = default_collider(k);
        return all;
    }();
    return collider_fields(const_cast<Collider&>(defaults[kind]));
}

std::string describe_allowed(const ColliderField& field) {
    return describe_allowed_as(field.unit, field.min, field.max, field.ref);
}

std::string format_value(const ColliderField& field) {
    return format_ref(std::visit([](auto* v) -> ConstFieldRef { return v; }, field.ref));
}

int find_collider_kind(std::string_view name) {
    if (name == "cube") name = "box";
    if (name == "ground") name = "plane";
    const auto names = collider_kind_names();
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (names[i] == name) return static_cast<int>(i);
    }
    return -1;
}

Collider& first_form_collider(ColliderSettings& colliders, std::string_view section) {
    const auto rank = [](std::size_t kind) {
        const auto order = kFirstFormSections;
        for (std::size_t r = 0; r < order.size(); ++r) {
            if (static_cast<int>(kind) == find_collider_kind(order[r])) return r;
        }
        return order.size();
    };
    const int kind = find_collider_kind(section);
    std::vector<Collider>& list = colliders.shapes;
    for (Collider& c : list) {
        if (static_cast<int>(c.kind()) == kind) return c;
    }
    // Before the first collider of a kind the first form resolved later, so an old file keeps its order.
    auto at = std::find_if(list.begin(), list.end(),
                           [&](const Collider& c) { return rank(c.kind()) > rank(static_cast<std::size_t>(kind)); });
    Collider added = default_collider(static_cast<std::size_t>(kind));
    added.enabled = false;
    return *list.insert(at, added);
}

}  // namespace clothsim
