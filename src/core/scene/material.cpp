#include "clothsim/material.hpp"

#include "scene/cloth_shape.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/cloth_mesh.hpp"
#include "model/membrane.hpp"

#include <array>
#include <optional>
#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>
#include <cstdio>
#include <string>
#include <string_view>

namespace clothsim {
namespace {

// Measured fabrics. Every number and its source: docs/MATERIAL.md, "Presets". A Wang et al. 2011 fabric is its
// released file's zero-strain row as ARCSim's forces read it (docs/MATERIAL.md, "Wang et al.'s files"): the
// tensile stiffness with the other direction free, 2 (c11 - c12^2 / c22) and 2 (c22 - c12^2 / c11) with c12
// clamped to 0; shear c33; bending the lowest-curvature sample along warp and weft over 3. A Matsudaira et al.
// 2015 fabric is its KES B (1 gf cm^2/cm = 9.80665e-5 N m) and weight, with the stretch and shear of the
// closest fabric Wang et al. measured.
// clang-format off
// Wang et al. 2011's stretching rows (c11, c12, c22, c33 in N/m) as their released files hold them (ARCSim's
// materials/*.json): the zero-strain row, then a principal stretch of 7/6 along 0, 22.5, 45, 67.5, 90 degrees.
// The curved presets' stretch curves come from these (stretch_curve.hpp, wang_stretch_samples).
constexpr WangStretching kWang_11oz_black_denim = {{{205.352005, 10.234077, 1013.88629, 53.387184}, {232.027634, 40.646339, 1052.84289, 64.980499},
    {224.592209, 40.384563, 1054.43444, 67.184807}, {225.951050, 62.095657, 1059.59741, 83.992020},
    {226.039566, 40.502792, 1058.27771, 75.118423}, {225.767487, 40.917892, 1051.55712, 71.810631}}};
constexpr WangStretching kWang_camel_ponte_roma = {{{31.146198, -12.802702, 44.028667, 31.896357}, {78.707756, 26.754574, 268.680725, 27.743423},
    {67.368431, 77.767944, 182.273407, -14.661531}, {113.367035, 54.802021, 175.126572, 44.657330},
    {144.294830, 111.404854, 138.422150, -29.861851}, {143.933365, 49.654823, 191.777588, 39.491055}}};
constexpr WangStretching kWang_gray_interlock = {{{16.593832, -14.695990, 34.477123, 36.860302}, {46.364765, 53.694656, 261.013855, -29.691301},
    {49.285110, 87.596100, 206.373993, 22.768457}, {123.989220, 105.181770, 365.966217, 44.217571},
    {139.686325, 73.592560, 413.553162, -174.43853}, {127.443810, 85.848587, 405.872833, 32.238411}}};
constexpr WangStretching kWang_ivory_rib_knit = {{{42.871021, -0.234556, 65.166023, 83.175644}, {52.422512, 7.219094, 245.337158, -31.129513},
    {29.482058, -5.146112, 127.130753, 13.068157}, {91.209549, 4.940307, 109.746452, 27.609430},
    {48.973385, -0.967226, 147.696823, -49.282963}, {105.649139, 0.416488, 254.593491, 3.472504}}};
constexpr WangStretching kWang_pink_ribbon_brown = {{{151.503906, 106.028160, 244.830673, 30.250183}, {164.124344, 33.689709, 268.195221, 30.074625},
    {152.584641, 107.251373, 210.614838, -62.760571}, {209.604172, 175.223465, 220.198120, 129.643188},
    {98.879021, 107.085518, 326.209442, 44.475986}, {96.805817, 54.626881, 359.792633, 30.340616}}};
constexpr WangStretching kWang_royal_target = {{{2016.55456, 9.170511, 2034.97644, 104.759674}, {2109.51684, 38.604588, 2173.93969, 19.129177},
    {2109.78002, 60.165310, 2155.51367, 27.817890}, {2110.33349, 30.987429, 2135.07910, 121.482445},
    {2109.16015, 72.393326, 2124.13525, 40.810982}, {2109.52612, 63.424015, 2152.73852, 39.885654}}};
constexpr WangStretching kWang_tango_red_jet_set = {{{43.067627, 54.373299, 171.424835, 14.314700}, {75.151695, 82.195221, 236.163773, -7.230383},
    {57.548206, 89.637825, 224.553848, 3.932043}, {107.244377, 124.801788, 364.583557, 41.386868},
    {178.734039, 178.488907, 371.764618, -30.898058}, {227.028687, -21.865427, 404.867188, 62.636021}}};
constexpr WangStretching kWang_white_dots_on_blk = {{{2002.08618, 0.345588, 2027.48559, 19.189022}, {2107.22753, 36.371597, 2171.73339, 16.904713},
    {2107.29882, 57.936157, 2153.30712, 24.392872}, {2107.73291, 28.389059, 2132.72607, 101.462021},
    {2106.93750, 70.149529, 2121.87353, 38.054455}, {2107.30786, 61.216290, 2150.47680, 37.668823}}};
constexpr WangStretching kWang_white_swim_solid = {{{47.971176, 6.834521, 104.615456, 60.773663}, {40.369045, 23.092957, 169.666290, -24.681890},
    {40.291599, 48.142597, 138.261612, 9.002558}, {51.393467, -32.966949, 79.881721, 35.973194},
    {51.500938, 1.868910, 63.693932, -37.540417}, {68.621185, 40.131950, 124.468513, 36.199604}}};
constexpr std::array kPresets = {
    MaterialPreset{"cotton-broadcloth", 0.124f, {4033.0f, 4070.0f}, 105.0f, {1.16e-5f, 1.16e-5f},
                   "cotton broadcloth: density, bending (Matsudaira et al. 2015, fabric A); stretch, shear of "
                   "the closest measured fabric, royal-target, a 65/35 cotton/polyester (Wang et al. 2011)"},
    MaterialPreset{"denim", 0.324f, {8891.0f, 8891.0f}, 122.5f, {1.69e-5f, 1.69e-5f},
                   "denim: KES-F of sample A (Kumari & Khurana 2016: stretch as the 0-500 gf/cm secant, shear, "
                   "bending); density of an 11 oz denim (Wang et al. 2011)"},
    MaterialPreset{"polyester-faille", 0.104f, {51.6f, 205.6f}, 14.3f, {1.86e-6f, 1.86e-6f},
                   "polyester faille: density, bending (Matsudaira et al. 2015, fabric F); stretch, shear of "
                   "the closest measured fabric, tango-red-jet-set, a light 100% polyester (Wang et al. 2011)"},
    MaterialPreset{"gray-interlock", 0.187f, {33.2f, 69.0f}, 36.9f, {7.73e-6f, 4.76e-6f},
                   "gray interlock, a 60/40 cotton/polyester interlock knit (t-shirt): every field measured "
                   "(Wang et al. 2011)", &kWang_gray_interlock},
    MaterialPreset{"wool-tropical", 0.163f, {4004.0f, 4055.0f}, 19.2f, {6.57e-6f, 6.57e-6f},
                   "wool tropical, a 100% wool plain weave: density, bending (Matsudaira et al. 2015, fabric B); "
                   "stretch, shear of the closest measured fabric, white-dots-on-blk, a woven 100% polyester (Wang et "
                   "al. 2011)"},
    MaterialPreset{"polyester-tropical", 0.117f, {4004.0f, 4055.0f}, 19.2f, {7.55e-6f, 7.55e-6f},
                   "polyester tropical: density, bending (Matsudaira et al. 2015, fabric C); stretch, shear of "
                   "the closest measured fabric, white-dots-on-blk, a 100% polyester (Wang et al. 2011)"},
    MaterialPreset{"11oz-black-denim", 0.324f, {410.5f, 2026.8f}, 53.4f, {2.14e-5f, 3.23e-5f},
                   "11 oz black denim, 99/1 cotton/spandex (jeans): every field measured (Wang et al. 2011)", &kWang_11oz_black_denim},
    MaterialPreset{"camel-ponte-roma", 0.284f, {62.3f, 88.1f}, 31.9f, {1.21e-5f, 1.24e-5f},
                   "camel ponte roma, a 60/40 polyester/rayon knit (jacket): every field measured (Wang et al. "
                   "2011)", &kWang_camel_ponte_roma},
    MaterialPreset{"ivory-rib-knit", 0.276f, {85.7f, 130.3f}, 83.2f, {1.54e-5f, 1.07e-5f},
                   "ivory rib knit, 95/5 cotton/spandex (underwear): every field measured (Wang et al. 2011)", &kWang_ivory_rib_knit},
    MaterialPreset{"pink-ribbon-brown", 0.228f, {211.2f, 341.3f}, 30.3f, {3.90e-5f, 1.99e-5f},
                   "pink ribbon brown, a 100% polyester (blanket): every field measured (Wang et al. 2011)", &kWang_pink_ribbon_brown},
    MaterialPreset{"royal-target", 0.220f, {4033.0f, 4070.0f}, 105.0f, {4.18e-5f, 4.18e-5f},
                   "royal target, a 65/35 cotton/polyester (pants): every field measured (Wang et al. 2011)", &kWang_royal_target},
    MaterialPreset{"tango-red-jet-set", 0.113f, {51.6f, 205.6f}, 14.3f, {4.76e-6f, 6.78e-6f},
                   "tango red jet set, a 100% polyester (jacket): every field measured (Wang et al. 2011)", &kWang_tango_red_jet_set},
    MaterialPreset{"white-dots-on-blk", 0.128f, {4004.0f, 4055.0f}, 19.2f, {1.72e-5f, 1.04e-5f},
                   "white dots on black, a 100% polyester (tablecloth): every field measured (Wang et al. 2011)", &kWang_white_dots_on_blk},
    MaterialPreset{"white-swim-solid", 0.204f, {95.1f, 207.3f}, 60.8f, {2.01e-5f, 1.70e-5f},
                   "white swim solid, 87/13 nylon/spandex (swimsuit): every field measured (Wang et al. 2011)", &kWang_white_swim_solid},
};
// Names the presets had. Each still loads, with a note: two named fabrics that were never measured (silk,
// wool jersey) and stood in for by the fabrics now named, and two names of a fibre for one fabric of it.
struct PresetAlias {
    std::string_view old_name, name, why;
};
constexpr std::array kPresetAliases = {
    PresetAlias{"cotton", "cotton-broadcloth", "the cotton fabric measured"},
    PresetAlias{"polyester", "polyester-tropical", "the polyester fabric measured"},
    PresetAlias{"silk", "polyester-faille", "no silk was measured; it is the fabric that stood in for silk"},
    PresetAlias{"wool-jersey", "gray-interlock", "no wool jersey was measured; it is the cotton/polyester knit that "
                                                 "stood in for wool jersey"},
};
// clang-format on

struct FieldBit {
    std::string_view name;
    unsigned bit;
};
constexpr std::array<FieldBit, 5> kMaterialFields = {{{"material.density", kMaterialDensity},
                                                      {"material.stretch", kMaterialStretch},
                                                      {"material.shear", kMaterialShear},
                                                      {"material.bending", kMaterialBending},
                                                      {"material.stretch_curve", kMaterialStretchCurve}}};
constexpr std::array<FieldBit, 4> kPerSpringFields = {{{"cloth.mass", kClothMass},
                                                       {"springs.structural", kSpringsStructural},
                                                       {"springs.shear", kSpringsShear},
                                                       {"springs.bending", kSpringsBending}}};

void apply_preset(MaterialSettings& m) {
    const MaterialPreset* p = find_material_preset(m.preset);
    if (!p) return;
    if (!(m.explicit_fields & kMaterialDensity)) m.density = p->density;
    if (!(m.explicit_fields & kMaterialStretch)) m.stretch = p->stretch;
    if (!(m.explicit_fields & kMaterialShear)) m.shear = p->shear;
    if (!(m.explicit_fields & kMaterialBending)) m.bending = p->bending;
    if (!(m.explicit_fields & kMaterialStretchCurve)) m.stretch_curve = preset_stretch_curve(*p);
}

std::string show(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", v);
    return buffer;
}

template <std::size_t N>
std::string join(const std::array<FieldBit, N>& fields, unsigned bits) {
    std::string s;
    for (const FieldBit& f : fields) {
        if (bits & f.bit) s += (s.empty() ? "" : ", ") + std::string(f.name);
    }
    return s;
}

}  // namespace

std::span<const MaterialPreset> material_presets() { return kPresets; }

StretchCurve preset_stretch_curve(const MaterialPreset& preset) {
    if (!preset.stretching) return {};
    return {wang_stretch_samples(*preset.stretching, false), wang_stretch_samples(*preset.stretching, true)};
}

namespace {

const PresetAlias* alias_of(std::string_view old_name) {
    for (const PresetAlias& a : kPresetAliases) {
        if (a.old_name == old_name) return &a;
    }
    return nullptr;
}

}  // namespace

const MaterialPreset* find_material_preset(std::string_view name) {
    if (const PresetAlias* a = alias_of(name)) name = a->name;
    for (const MaterialPreset& p : kPresets) {
        if (p.name == name) return &p;
    }
    return nullptr;
}

std::optional<std::string> material_preset_alias_note(std::string_view name) {
    const PresetAlias* a = alias_of(name);
    if (!a) return std::nullopt;
    return "material.preset = \"" + std::string(a->old_name) + "\" is an old name: it loads \"" + std::string(a->name) +
           "\" (" + std::string(a->why) + ")";
}

glm::dvec2 grid_spacing(const ClothSettings& cloth) {
    return {cloth.cols > 1 ? double(cloth.size.x) / (cloth.cols - 1) : 0.0,
            cloth.rows > 1 ? double(cloth.size.y) / (cloth.rows - 1) : 0.0};
}

SpringConstants spring_constants(const ClothSettings& cloth, const MaterialSettings& material) {
    if (cloth.rows < 2 || cloth.cols < 2) {
        throw SceneError("cloth.rows = " + std::to_string(cloth.rows) + ", cloth.cols = " + std::to_string(cloth.cols) +
                         " has no cells for [material] to fill; allowed with [material]: at least 2 x 2 particles");
    }
    const glm::dvec2 h = grid_spacing(cloth);
    const double hu = h.x, hv = h.y;
    const double su = material.stretch.x, sv = material.stretch.y, g = material.shear;
    SpringConstants out;
    // Uniaxial stiffness along u is C11 - G^2 / C22 and along v C22 - G^2 / C11 (C12 = G), both the targets: the
    // tensor a mesh cloth's membrane triangles take too (membrane.hpp).
    const MembraneTensor tensor = membrane_tensor(su, sv, g);
    const double c22 = tensor.c22;
    const double c11 = tensor.c11;
    double au = c11 - g * (hu / hv) * (hu / hv);
    double av = c22 - g * (hv / hu) * (hv / hu);
    // On long thin cells the diagonals alone may be stiffer in tension along the short side than the stretch
    // asked for: the structural springs there cannot be negative, so that axis comes out stiffer than asked.
    const bool clamp_u = au < 0.0, clamp_v = av < 0.0;
    au = std::max(au, 0.0), av = std::max(av, 0.0);
    const double cu = au + g * (hu / hv) * (hu / hv), cv = av + g * (hv / hu) * (hv / hu);
    for (const auto& [clamped, axis, got, asked] :
         {std::tuple{clamp_u, "u", cu - g * g / cv, su}, std::tuple{clamp_v, "v", cv - g * g / cu, sv}}) {
        if (!clamped) continue;
        out.note += std::string(out.note.empty() ? "" : "; ") + "on cells of " + show(hu) + " x " + show(hv) +
                    " m the diagonals alone (material.shear = " + show(g) + " N/m) give a stretch of " + show(got) +
                    " N/m along " + axis + ", more than the " + show(asked) + " asked: make the cells closer to square";
    }
    out.structural = {au * hv / hu, av * hu / hv};
    out.shear = g * (hu * hu + hv * hv) / (2.0 * hu * hv);
    out.bending = {double(material.bending.x) * hv / (hu * hu * hu), double(material.bending.y) * hu / (hv * hv * hv)};
    out.poisson_uv = g / cv;
    out.poisson_vu = g / cu;
    out.total_mass = double(material.density) * hu * hv * double(shape_mask(cloth).cell_count);
    return out;
}

void note_field_set(Scene& scene, std::string_view field) {
    MaterialSettings& m = scene.material;
    if (field == "material.enabled") {
        // Off: the per-spring form, holding the mass and constants last derived; nothing of the material is kept.
        if (!m.enabled) {
            m = MaterialSettings{};
            scene.settings.springs.stretch_curve = {};  // the per-spring form is linear
            scene.settings.springs.mesh_curve = {};
            scene.settings.springs.membrane_curve = {};
        }
        return;
    }
    if (field == "material.preset") {
        m.enabled = true;
        if (std::optional<std::string> note = material_preset_alias_note(m.preset)) {
            m.preset = alias_of(m.preset)->name;  // saved under the name of what it is
            scene.notes.push_back(std::move(*note));
        }
        apply_preset(m);
        return;
    }
    for (const FieldBit& f : kMaterialFields) {
        if (field == f.name) {
            m.enabled = true;
            m.explicit_fields |= f.bit;
            return;
        }
    }
    for (const FieldBit& f : kPerSpringFields) {
        if (field == f.name) scene.per_spring_fields |= f.bit;
    }
}

void derive_springs(Scene& scene) {
    if (!scene.material.enabled || !material_clash(scene).empty()) return;
    if (scene.cloth.is_mesh()) {
        // A mesh cloth's elements carry their geometry in their weights (cloth_mesh.hpp): the springs' k is the
        // stretch times theirs, the hinges' the flexural rigidity times theirs.
        SpringSettings& s = scene.settings.springs;
        s.structural = scene.material.stretch;
        s.shear = scene.material.shear;
        s.bending = scene.material.bending;
        // Its edges mix warp and weft: a curve per warp level (stretch_curve.hpp, mesh_curves).
        s.stretch_curve = {};
        if (scene.cloth.membrane == MembraneModel::Triangles) {
            // The triangles' own directions: each curve on its tensor entry (C11 along u, C22 along v).
            const MembraneTensor c = membrane_tensor(scene.material.stretch.x, scene.material.stretch.y, scene.material.shear);
            s.mesh_curve = {};
            s.membrane_curve = {spring_curve(scene.material.stretch_curve.u, scene.material.stretch.x, c.c11),
                                spring_curve(scene.material.stretch_curve.v, scene.material.stretch.y, c.c22)};
        } else {
            s.mesh_curve = mesh_curves(scene.material.stretch_curve, scene.material.stretch.x, scene.material.stretch.y);
            s.membrane_curve = {};
        }
        double area = 0.0;
        if (scene.cloth.mesh_data) {
            for (double a : vertex_areas(placed_cloth_vertices(scene.cloth), scene.cloth.mesh_data->triangles())) area += a;
        }
        if (area > 0.0) scene.cloth.mass = static_cast<float>(double(scene.material.density) * area);
        return;
    }
    const SpringConstants k = spring_constants(scene.cloth, scene.material);
    SpringSettings& s = scene.settings.springs;
    s.structural = glm::vec2(k.structural);
    s.shear = static_cast<float>(k.shear);
    s.bending = glm::vec2(k.bending);
    // The curves' tangent factors on the structural springs' share of the membrane's stretch (a_u = k_u h_u / h_v
    // of C11; stretch_curve.hpp): a factor m along u makes the tensile tangent m material.stretch.
    const glm::dvec2 h = grid_spacing(scene.cloth);
    s.stretch_curve = {spring_curve(scene.material.stretch_curve.u, scene.material.stretch.x, k.structural.x * h.x / h.y),
                       spring_curve(scene.material.stretch_curve.v, scene.material.stretch.y, k.structural.y * h.y / h.x)};
    s.mesh_curve = {};
    s.membrane_curve = {};
    scene.cloth.mass = static_cast<float>(k.total_mass);
}

std::string material_clash(const Scene& scene) {
    const MaterialSettings& m = scene.material;
    if (!m.preset.empty() && !find_material_preset(m.preset)) {
        std::string names;
        for (const MaterialPreset& p : kPresets) names += (names.empty() ? "" : ", ") + std::string(p.name);
        return "material.preset = \"" + m.preset + "\" is not a known fabric; allowed: " + names;
    }
    if (!m.enabled || scene.per_spring_fields == 0) return "";
    std::string material_fields = m.preset.empty() ? "" : "material.preset";
    if (const std::string set = join(kMaterialFields, m.explicit_fields); !set.empty()) {
        material_fields += (material_fields.empty() ? "" : ", ") + set;
    }
    return "material: " + join(kPerSpringFields, scene.per_spring_fields) + " and " + material_fields +
           " both describe the cloth's mass and stiffness; allowed: one form, either [material] (density, stretch, "
           "shear, bending in physical units) or cloth.mass with springs.structural/shear/bending (per spring)";
}

bool field_is_written(const Scene& scene, std::string_view field) {
    const MaterialSettings& m = scene.material;
    if (field.starts_with("material.")) {
        if (!m.enabled) return false;
        if (field == "material.enabled") return true;
        if (field == "material.preset") return !m.preset.empty();
        for (const FieldBit& f : kMaterialFields) {
            if (field == f.name) return m.preset.empty() || (m.explicit_fields & f.bit);
        }
        return true;
    }
    if (m.enabled) {
        for (const FieldBit& f : kPerSpringFields) {
            if (field == f.name) return false;
        }
    }
    return true;
}

}  // namespace clothsim
