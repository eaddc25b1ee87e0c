// The settings panel (Dear ImGui). Scene fields are drawn from the field table (scene_fields.cpp), so each
// widget's tooltip gives the field's unit, meaning and allowed range, and each field can be reset to the
// loaded scene's value or the built-in default (right-click, or the small button that appears once changed).
#include "app_state.hpp"
#include "layout.hpp"

#include "clothsim/cloth_mesh.hpp"
#include "clothsim/material.hpp"
#include "clothsim/mesh_file.hpp"
#include "clothsim/overloaded.hpp"
#include "clothsim/stability.hpp"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string_view>
#include <type_traits>
#include <variant>

namespace clothsim {
namespace {

// Slider extents for fields whose valid range is too wide to drag through (the valid range still applies:
// ctrl+click types any allowed value).
struct SliderHint {
    const char* field;
    float lo, hi;
    bool logarithmic;
};
constexpr SliderHint kHints[] = {
    {"springs.structural", 1.0f, 1e6f, true}, {"springs.shear", 0.0f, 1e6f, true},
    {"springs.bending", 0.0f, 1e5f, true},    {"springs.damping", 0.0f, 100.0f, true},
    {"forces.drag", 0.0f, 10.0f, true},       {"cloth.mass", 0.001f, 100.0f, true},
    {"integration.dt", 1e-4f, 0.1f, true},    {"colliders.thickness", 0.0f, 0.05f, false},
    {"integration.tolerance", 1e-10f, 1e-2f, true}, {"springs.strain_limit", 0.0f, 1.0f, false},
    {"springs.tether_strain", 0.0f, 0.1f, false},
    {"forces.max_speed", 0.0f, 100.0f, false}, {"solver.sleep_speed", 0.0f, 0.1f, true},
    {"solver.sleep_time", 0.0f, 10.0f, false}, {"colliders.contact_stiffness", 10.0f, 1e6f, true},
    {"material.density", 0.01f, 2.0f, true},  {"material.shear", 0.0f, 1e5f, true},
    {"material.stretch", 1.0f, 1e5f, true},   {"material.bending", 0.0f, 1e-2f, true},
    {"collision.self_thickness", 0.0f, 0.1f, false}, {"collision.self_friction", 0.0f, 2.0f, false},
    {"springs.tear_strain", 0.0f, 2.0f, false},
};

const SliderHint* hint_for(std::string_view name) {
    for (const SliderHint& h : kHints) {
        if (name == h.field) return &h;
    }
    return nullptr;
}

void tooltip(const FieldInfo& f) {
    if (!ImGui::IsItemHovered()) return;
    ImGui::BeginTooltip();
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 28.0f);
    ImGui::TextUnformatted(std::string(f.name).c_str());
    ImGui::TextUnformatted(std::string(f.help).c_str());
    if (!f.unit.empty()) ImGui::Text("unit: %s", std::string(f.unit).c_str());
    ImGui::TextDisabled("allowed: %s", describe_allowed(f).c_str());
    ImGui::TextDisabled("ctrl+click to type a value; right-click to reset");
    ImGui::PopTextWrapPos();
    ImGui::EndTooltip();
}

// A combo box over an enumeration's names (as written in scene files); true when the user picked one.
template <class Enum>
bool enum_combo(const char* label, Enum* value, std::span<const std::string_view> names) {
    const int current = static_cast<int>(*value);
    bool edited = false;
    if (ImGui::BeginCombo(label, std::string(names[current]).c_str())) {
        for (int i = 0; i < static_cast<int>(names.size()); ++i) {
            if (ImGui::Selectable(std::string(names[i]).c_str(), i == current)) {
                *value = static_cast<Enum>(i);
                edited = true;
            }
        }
        ImGui::EndCombo();
    }
    return edited;
}

// The label shown for a field: its last name component in words, with its unit ("tether strain",
// "damping (1/s)"); the dotted name is the tooltip's first line.
std::string label_of(const FieldInfo& f) {
    const auto dot = f.name.rfind('.');
    std::string label(dot == std::string_view::npos ? f.name : f.name.substr(dot + 1));
    std::replace(label.begin(), label.end(), '_', ' ');
    if (!f.unit.empty()) label += " (" + std::string(f.unit) + ")";
    return label;
}

// A float field: a slider over the hinted extent (logarithmic where the range spans decades), else a drag.
// A typed value (ctrl+click) is not clamped here: keep_in_range clamps it to the field's range with a note.
bool float_widget(const std::string& label, const FieldInfo& f, float* v) {
    if (const SliderHint* h = hint_for(f.name)) {
        return ImGui::SliderFloat(label.c_str(), v, h->lo, h->hi, "%.4g",
                                  h->logarithmic ? ImGuiSliderFlags_Logarithmic : 0);
    }
    const float speed = std::max(std::fabs(*v) * 0.01f, 0.001f);
    return ImGui::DragFloat(label.c_str(), v, speed, static_cast<float>(f.min), static_cast<float>(f.max), "%.4g");
}

// The pins: a preset picked in a combo (which drops the particles pinned by hand and keeps the preset's clip
// radius), and below the presets whether clips hold softly. The preview shows the clip radius and how many pins
// were added by hand ("top-corners, soft clip 0.03 m + 2").
// material.stretch_curve: a checkbox between linear ({}) and the preset's measured curve (a curve of one's own
// comes from the scene file or --set); the samples show as a tooltip.
bool stretch_curve_toggle(const std::string& label, const Scene& edit, StretchCurve* v) {
    const MaterialPreset* preset = find_material_preset(edit.material.preset);
    const StretchCurve measured = preset ? preset_stretch_curve(*preset) : StretchCurve{};
    bool curved = !v->empty();
    const bool can = curved || !measured.empty();
    ImGui::BeginDisabled(!can);
    const bool changed = ImGui::Checkbox(label.c_str(), &curved);
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
        const FieldInfo* f = find_field("material.stretch_curve");
        ImGui::SetTooltip("%s", v->empty() ? (can ? "linear: tick for the preset's measured curve"
                                                  : "linear: this preset has no measured curve")
                                           : format_value(edit, *f).c_str());
    }
    if (changed) *v = curved ? measured : StretchCurve{};
    return changed;
}

bool pin_combo(const std::string& label, PinSpec* v) {
    const int preset = static_cast<int>(v->preset);
    const auto names = pin_preset_names();
    char clip[48] = "";
    const char* kind = v->clip == ClipKind::Soft ? "soft clip" : "clip";
    if (v->preset_radius > 0.0f) std::snprintf(clip, sizeof clip, ", %s %.3g m", kind, v->preset_radius);
    const std::string preview = std::string(names[preset]) + clip +
                                (v->particles.empty() ? "" : " + " + std::to_string(v->particles.size()));
    bool edited = false;
    if (ImGui::BeginCombo(label.c_str(), preview.c_str())) {
        for (int i = 0; i < static_cast<int>(names.size()); ++i) {
            if (ImGui::Selectable(std::string(names[i]).c_str(), i == preset && v->particles.empty())) {
                v->preset = static_cast<PinPreset>(i);
                v->particles.clear();
                if (v->preset == PinPreset::None || v->preset_radius == 0.0f) {
                    v->clip = ClipKind::Rigid;  // no clip left to hold softly
                }
                edited = true;
            }
        }
        ImGui::Separator();
        // Only clips (pins with a radius) can be soft; point pins stay rigid, so without a clip the switch is
        // shown but cannot be used.
        const bool clips = (v->preset != PinPreset::None && v->preset_radius > 0.0f) ||
                           std::any_of(v->particles.begin(), v->particles.end(), [](const Pin& p) { return p.radius > 0.0f; });
        bool soft = v->clip == ClipKind::Soft;
        ImGui::BeginDisabled(!clips && !soft);
        if (ImGui::Checkbox("soft clips", &soft)) {
            v->clip = soft ? ClipKind::Soft : ClipKind::Rigid;
            edited = true;
        }
        ImGui::EndDisabled();
        if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
            ImGui::SetTooltip(clips ? "Hold each clip's particles by springs that fade to 0 at its rim instead of pinning them"
                                    : "Only clips can be soft: give the pins a radius (pins = { ..., radius = R })");
        }
        ImGui::EndCombo();
    }
    return edited;
}

// Draws the widget for one field's value in `edit`; returns true when the user changed it.
bool value_widget(Scene& edit, const FieldInfo& f) {
    const std::string label = label_of(f);
    return std::visit(
        Overloaded{
            [&](int* v) {
                return ImGui::DragInt(label.c_str(), v, 0.2f, static_cast<int>(f.min), static_cast<int>(f.max), "%d");
            },
            [&](float* v) { return float_widget(label, f, v); },
            [&](bool* v) { return ImGui::Checkbox(label.c_str(), v); },
            [&](glm::vec2* v) {
                if (const SliderHint* h = hint_for(f.name)) {
                    return ImGui::SliderFloat2(label.c_str(), &v->x, h->lo, h->hi, "%.4g",
                                               h->logarithmic ? ImGuiSliderFlags_Logarithmic : 0);
                }
                // Stiffnesses span decades: a drag moves them by a fraction of their size.
                const bool stiffness = f.name == "material.stretch" || f.name == "material.bending" ||
                                       f.name.starts_with("springs.");
                const float speed = stiffness ? std::max(0.01f * std::max(v->x, v->y), 1e-9f) : 0.01f;
                return ImGui::DragFloat2(label.c_str(), &v->x, speed, static_cast<float>(f.min),
                                         static_cast<float>(f.max), "%.4g");
            },
            [&](glm::vec3* v) {
                const float speed = std::max(0.005f, 0.01f * std::max({std::fabs(v->x), std::fabs(v->y), std::fabs(v->z)}));
                return ImGui::DragFloat3(label.c_str(), &v->x, speed, static_cast<float>(f.min),
                                         static_cast<float>(f.max), "%.3g");
            },
            [&](std::string* v) {
                char buffer[256];
                std::snprintf(buffer, sizeof buffer, "%s", v->c_str());
                // A file is read when the name is complete (Enter), not at every key.
                const ImGuiInputTextFlags flags = f.name == "cloth.mesh" ? ImGuiInputTextFlags_EnterReturnsTrue : 0;
                if (ImGui::InputText(label.c_str(), buffer, sizeof buffer, flags)) {
                    *v = buffer;
                    return true;
                }
                return false;
            },
            [&](PinSpec* v) { return pin_combo(label, v); },
            [&](StretchCurve* v) { return stretch_curve_toggle(label, edit, v); },
            [&]<class Enum>(Enum* v) requires std::is_enum_v<Enum> { return enum_combo(label.c_str(), v, names_of(v)); },
        },
        f.ref(edit));
}

// Reset for the last widget: a right-click menu (the loaded scene's value or the built-in default), and a
// small button once the value differs from the loaded scene's. Returns true when it reset the field.
bool reset_controls(Scene& edit, const Scene& loaded, const FieldInfo& f) {
    bool changed = false;
    const std::string scene_value = format_value(loaded, f);
    if (ImGui::BeginPopupContextItem("reset")) {
        if (ImGui::MenuItem(("Reset to scene value " + scene_value).c_str())) {
            copy_field(f, loaded, edit);
            changed = true;
        }
        if (ImGui::MenuItem(("Reset to built-in default " + format_value(Scene{}, f)).c_str())) {
            copy_field(f, Scene{}, edit);
            changed = true;
        }
        ImGui::EndPopup();
    }
    if (format_value(edit, f) != scene_value) {
        ImGui::SameLine();
        if (ImGui::SmallButton("reset")) {
            copy_field(f, loaded, edit);
            changed = true;
        }
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("back to the scene's value %s", scene_value.c_str());
    }
    return changed;
}

// One field: its widget, its tooltip and its reset controls; returns true when the user changed it.
bool field_widget(Scene& edit, const Scene& loaded, const FieldInfo& f) {
    ImGui::PushID(f.name.data(), f.name.data() + f.name.size());
    bool changed = value_widget(edit, f);
    tooltip(f);
    changed |= reset_controls(edit, loaded, f);
    ImGui::PopID();
    return changed;
}

// Clamps a field the user just edited into its allowed range (the loader's table), with a note when it did.
void keep_in_range(AppState& app, Scene& edit, const FieldInfo& f) {
    if (auto note = clamp_to_range(edit, f)) app.say(*note, true);
}

// After an edit of `f`: the material bookkeeping (material.hpp) and the springs it derives. A material the
// grid cannot hold is left to the rebuild, which says why and keeps the running cloth.
void note_edit(Scene& edit, const FieldInfo& f) {
    note_field_set(edit, f.name);
    try {
        derive_springs(edit);
    } catch (const SceneError&) {
    }
}

// One field's row: its widget with tooltip and reset controls, its range check and the material
// bookkeeping; returns true when the user changed it.
bool field_row(Scene& edit, AppState& app, const FieldInfo& f) {
    // Auto substeps owns the substeps field: greyed out so an edit is not silently overwritten.
    const bool owned = app.stepper.policy().auto_substeps && f.name == "integration.substeps";
    // A solver setting the chosen integrator does not read stays editable but dimmed (as Blender shows an
    // inactive property), and its tooltip says so.
    const Integrator integrator = edit.settings.integration.integrator;
    const bool unused = (f.name == "integration.tolerance" && !uses_tolerance(integrator)) ||
                        (f.name == "integration.iterations" && !uses_iterations(integrator));
    // A mesh cloth does not read the grid's fields, nor a grid the mesh's placement.
    const bool grid_field = f.name == "cloth.rows" || f.name == "cloth.cols" || f.name == "cloth.size" ||
                            f.name == "cloth.shape" || f.name == "cloth.v_axis";
    const bool mesh_field = f.name == "cloth.mesh_rotation" || f.name == "cloth.mesh_scale" || f.name == "cloth.membrane";
    const bool unread = edit.cloth.is_mesh() ? grid_field : mesh_field;
    bool changed = false;
    if (owned) ImGui::BeginDisabled();
    if (unused || unread) ImGui::PushStyleVar(ImGuiStyleVar_Alpha, ImGui::GetStyle().Alpha * 0.45f);
    if (owned ? value_widget(edit, f) : field_widget(edit, app.loaded, f)) {
        keep_in_range(app, edit, f);
        note_edit(edit, f);
        changed = true;
        if (f.name == "cloth.mesh") {  // read the file now; a bad one is said and the cloth stays as it is
            try {
                load_cloth_mesh(edit.cloth, scene_file_directory(app.scene_source));
            } catch (const SceneError& e) {
                app.say(e.what());
                edit.cloth.mesh = app.document().cloth.mesh;
                edit.cloth.mesh_data = app.document().cloth.mesh_data;
                changed = false;
            }
        }
    }
    if (unread) {
        ImGui::PopStyleVar();
        if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip(edit.cloth.is_mesh() ? "a mesh cloth (cloth.mesh) does not read %s"
                                                   : "%s places a mesh cloth; this cloth is a grid (cloth.mesh = \"\")",
                              std::string(f.name).c_str());
        }
    }
    if (unused) {
        ImGui::PopStyleVar();
        if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip("%s does not read %s",
                              std::string(integrator_names()[static_cast<int>(integrator)]).c_str(),
                              std::string(f.name).c_str());
        }
    }
    if (owned && ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
        ImGui::SetTooltip("auto substeps chooses integration.substeps (Integration: untick it to set them)");
    }
    if (owned) ImGui::EndDisabled();
    return changed;
}

// The fields the fabric part of the Springs section draws (fabric_section), left out of the other sections.
bool is_fabric_field(std::string_view name) {
    return name == "cloth.mass" || name == "springs.structural" || name == "springs.shear" ||
           name == "springs.bending" || name.starts_with("material.");
}

// Draws every field of `edit` whose name starts with `prefix` (the fabric's apart); returns true when any changed.
bool fields_section(Scene& edit, AppState& app, std::string_view prefix) {
    bool changed = false;
    for (const FieldInfo& f : scene_fields()) {
        if (!f.name.starts_with(prefix) || is_fabric_field(f.name)) continue;
        changed |= field_row(edit, app, f);
    }
    return changed;
}

// Draws the named fields of `edit` in this order; returns true when any changed.
bool named_fields(Scene& edit, AppState& app, std::initializer_list<std::string_view> names) {
    bool changed = false;
    for (std::string_view name : names) changed |= field_row(edit, app, *find_field(name));
    return changed;
}

// Under XPBD, a structural stiffness `k` (N/m per spring) above xpbd_rigid_stiffness at this substep projects
// nearly as a rigid rod: the stretch the user sees is the pass's, and dragging k changes little. Marked "(i)"
// on the line that shows k (SameLine: nothing below moves), with why and the substeps that would let k show.
void xpbd_rigid_marker(const AppState& app, double k) {
    const SimulationSettings& settings = app.sim.settings();
    if (settings.integration.integrator != Integrator::Xpbd || !(k > 0.0)) return;
    const Topology& topology = app.sim.topology();
    const State& state = app.sim.state();
    if (topology.rows <= 0 || topology.cols <= 0 || state.inverse_mass.empty()) return;
    // An inner particle: the grid's centre (the heaviest free particles, so the lowest ceiling's bound).
    const std::size_t centre = static_cast<std::size_t>(topology.rows / 2) * topology.cols + topology.cols / 2;
    const double w = centre < state.inverse_mass.size() ? state.inverse_mass[centre] : 0.0;
    const double h = app.sim.substep_length();
    if (!(w > 0.0) || !(h > 0.0)) return;
    const double ceiling = xpbd_rigid_stiffness(2.0 * w, h);
    if (k <= ceiling) return;
    // k shows once k <= 10 / (2 w h^2): h <= sqrt(10 / (2 w k)).
    const double substeps = std::ceil(settings.integration.dt / std::sqrt(10.0 / (2.0 * w * k)));
    ImGui::SameLine();
    ImGui::TextColored(ImVec4(0.5f, 0.8f, 1.0f, 1.0f), "(i)");
    if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("XPBD at %.3g ms substeps projects every structural spring stiffer than %.3g N/m as nearly "
                          "rigid:\nthe one pass per substep, not the stiffness, sets the stretch here, so changing it "
                          "shows little.\nAbout %.0f substeps per step would let %.4g N/m show (docs/STIFF_CLOTH.md).",
                          1e3 * h, ceiling, substeps, k);
    }
}

// The softer of the two directions' structural springs (one of them may be 0: the diagonals hold that axis).
double softest(glm::dvec2 k) {
    return std::min(k.x > 0.0 ? k.x : k.y, k.y > 0.0 ? k.y : k.x);
}

// What an edit of the fabric asks for.
enum class FabricEdit {
    None,
    Live,     // new values: masses and springs' k re-derived in place (apply_fabric)
    Rebuild,  // between the per-spring form and a material: bends replace skip-one springs
};

// The fabric, the cloth's mass and stiffness: per-spring values, a material of the scene's own, or a measured
// preset (material.hpp). Their values are live: the same cloth goes on moving with the new masses and
// constants. On a material the controls are the material's, in physical units, with the per-spring values
// they give on this grid beneath; on a per-spring cloth they are cloth.mass and the springs' k.
FabricEdit fabric_section(Scene& edit, AppState& app) {
    FabricEdit result = FabricEdit::None;
    const MaterialSettings& m = edit.material;
    const std::string current = !m.enabled ? "per spring" : m.preset.empty() ? "custom material" : m.preset;
    if (ImGui::BeginCombo("fabric", current.c_str())) {
        auto choose = [&](const std::string& name) {
            const bool was_material = edit.material.enabled;
            if (name == "per spring") {
                // Back to springs: the loaded scene's when it had them, else those derived on this grid (as
                // --set material.enabled=false does).
                edit.material.enabled = false;
                note_edit(edit, *find_field("material.enabled"));
                if (!app.loaded.material.enabled) {
                    edit.settings.springs.structural = app.loaded.settings.springs.structural;
                    edit.settings.springs.shear = app.loaded.settings.springs.shear;
                    edit.settings.springs.bending = app.loaded.settings.springs.bending;
                    edit.cloth.mass = app.loaded.cloth.mass;
                }
            } else {
                edit.per_spring_fields = 0;
                edit.material.enabled = true;
                edit.material.preset = name == "custom material" ? "" : name;
                // A preset is the whole fabric: every one of its fields, none of the scene's kept.
                if (!edit.material.preset.empty()) edit.material.explicit_fields = 0;
                note_edit(edit, *find_field("material.preset"));
            }
            result = was_material == edit.material.enabled ? FabricEdit::Live : FabricEdit::Rebuild;
        };
        for (const char* name : {"per spring", "custom material"}) {
            if (ImGui::Selectable(name, current == name)) choose(name);
        }
        for (const MaterialPreset& p : material_presets()) {
            const std::string name(p.name);
            if (ImGui::Selectable(name.c_str(), current == name)) choose(name);
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", std::string(p.note).c_str());
        }
        ImGui::EndCombo();
    }
    if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("per spring: cloth.mass and springs.* as numbers per spring (a finer grid is another "
                          "fabric);\nmaterial: density, stretch, shear and bending in physical units, the same "
                          "fabric at every resolution (docs/MATERIAL.md).\nValues change live; switching between "
                          "per spring and a material rebuilds the cloth");
    }
    if (result != FabricEdit::None) return result;
    if (edit.material.enabled) {
        // The stretch curve on the fabric's own row (SameLine: nothing below moves): linear or the preset's
        // measured curve (docs/MATERIAL.md, "Nonlinear stretch").
        ImGui::SameLine();
        if (stretch_curve_toggle("curved", edit, &edit.material.stretch_curve)) {
            note_edit(edit, *find_field("material.stretch_curve"));
            return FabricEdit::Live;
        }
    }
    if (edit.material.enabled) {
        if (named_fields(edit, app, {"material.density", "material.stretch", "material.shear", "material.bending"})) {
            result = FabricEdit::Live;
        }
        if (app.sim.topology().mesh) {
            // Two lines, as the grid's below, so nothing moves between scenes.
            if (!app.sim.topology().membranes.empty()) {
                ImGui::TextDisabled("mesh: constant-strain triangles, Bergou hinges");
                ImGui::TextDisabled("stretch and shear are the material's (i)");
                if (ImGui::IsItemHovered()) {
                    ImGui::SetTooltip("cloth.membrane = \"triangles\": each triangle carries the material's tensor, so a\n"
                                      "uniform strain of any triangulation stores what the continuum stores. docs/MESH_CLOTH.md");
                }
                return result;
            }
            ImGui::TextDisabled("mesh: van Gelder springs, Bergou hinges");
            ImGui::TextDisabled("on a mesh, shear is 3/8 of stretch (i)");
            if (ImGui::IsItemHovered()) {
                ImGui::SetTooltip("Springs on triangles are a central-force lattice: its shear stiffness is 3/8 of\n"
                                  "its tensile stiffness (the Cauchy relation); cloth.membrane = \"triangles\" gives\n"
                                  "shear its own modulus. docs/MESH_CLOTH.md");
            }
            return result;
        }
        try {
            const SpringConstants k = spring_constants(edit.cloth, edit.material);
            ImGui::TextDisabled("per spring: structural %.4g / %.4g, shear %.4g N/m", k.structural.x,
                                k.structural.y, k.shear);
            // A stretch the grid cannot give (the diagonals alone are stiffer): said in the message area while it
            // holds and marked on this line, so the rows below never move as a slider crosses it.
            if (!k.note.empty()) {
                ImGui::SameLine();
                ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "(!)");
                if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", k.note.c_str());
                app.say(k.note);
            }
            xpbd_rigid_marker(app, softest(k.structural));
            ImGui::TextDisabled("bends %.4g / %.4g N/m; Poisson ratio %.3f / %.3f", k.bending.x, k.bending.y,
                                k.poisson_uv, k.poisson_vu);
        } catch (const SceneError& e) {
            ImGui::TextWrapped("%s", e.what());
        }
    } else {
        if (named_fields(edit, app, {"cloth.mass", "springs.structural"})) result = FabricEdit::Live;
        xpbd_rigid_marker(app, softest(glm::dvec2(edit.settings.springs.structural)));
        if (named_fields(edit, app, {"springs.shear", "springs.bending"})) result = FabricEdit::Live;
    }
    return result;
}

// A live fabric edit reaches the running cloth (apply_fabric) and the document; one the cloth cannot take
// (a material the grid cannot hold) changes nothing and says why.
void put_fabric(AppState& app, Scene& edit) {
    try {
        apply_fabric(app.sim, edit);
    } catch (const SceneError& e) {
        app.say(std::string("fabric not changed: ") + e.what(), true);
        edit.settings.springs = app.sim.settings().springs;
        return;
    }
    app.scene.material = edit.material;
    app.scene.cloth.mass = edit.cloth.mass;
    app.scene.per_spring_fields = edit.per_spring_fields;
}

void plot(const char* label, const History& h, ImVec4 color) {
    char overlay[64];
    std::snprintf(overlay, sizeof overlay, "%s %.4g J", label, h.last());
    ImGui::PushStyleColor(ImGuiCol_PlotLines, color);
    ImGui::PlotLines("##energy", h.values.data(), h.size(), h.offset(), overlay, FLT_MAX, FLT_MAX,
                     ImVec2(ImGui::GetContentRegionAvail().x, 3.5f * ImGui::GetFontSize()));
    ImGui::PopStyleColor();
}

// Box2D-style step profile: every stage of the plan, its time per frame, and why a skipped one is skipped.
void profile_section(const AppState& app) {
    const StepProfile& frame = app.stats.profile;
    const SimulationSettings& settings = app.sim.settings();
    const ImVec4 grey(0.55f, 0.55f, 0.55f, 1.0f);
    if (app.sim.asleep()) {
        ImGui::TextColored(ImVec4(0.5f, 0.8f, 1.0f, 1.0f), "asleep: %lld substeps skipped this frame", frame.slept_substeps);
    } else if (app.sim.plan().may_sleep) {
        ImGui::Text("awake: calm for %.2f of %.2f s before sleeping", app.sim.calm_seconds(), settings.solver.sleep_time);
    } else {
        ImGui::TextDisabled("awake: sleeping is off (%s)",
                            settings.solver.sleep_speed > 0.0f ? "forces.wind blows" : "solver.sleep_speed is 0");
    }
    if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("The cloth sleeps once every free particle has moved slower than solver.sleep_speed\n"
                          "for solver.sleep_time with still air; any setting change, a grab or a pin wakes it.");
    }
    const ImGuiTableFlags flags = ImGuiTableFlags_SizingStretchProp | ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV;
    if (!ImGui::BeginTable("stages", 3, flags)) return;
    ImGui::TableSetupColumn("stage", ImGuiTableColumnFlags_WidthFixed);
    ImGui::TableSetupColumn("ms/frame", ImGuiTableColumnFlags_WidthFixed);
    ImGui::TableSetupColumn("runs / why not");
    ImGui::TableHeadersRow();
    auto row = [&](std::string_view name, StageState state, float ms, const std::string& note) {
        const bool runs = state == StageState::Runs;
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        if (runs) ImGui::TextUnformatted(name.data(), name.data() + name.size());
        else ImGui::TextColored(grey, "%.*s", static_cast<int>(name.size()), name.data());
        ImGui::TableNextColumn();
        if (runs) ImGui::Text("%.3f", ms);
        else ImGui::TextColored(grey, "-");
        ImGui::TableNextColumn();
        if (runs) ImGui::TextUnformatted(note.c_str());
        else if (state == StageState::Fused) ImGui::TextColored(grey, "%s", note.c_str());
        else ImGui::TextColored(grey, "skipped: %s", note.c_str());
        if (!note.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", note.c_str());
    };
    float total = 0.0f;
    for (const StageStatus& s : describe(app.sim.plan(), app.sim.topology(), settings)) {
        const std::size_t i = static_cast<std::size_t>(s.stage);
        total += app.stats.times.stage_ms[i];
        row(stage_name(s.stage), s.state, app.stats.times.stage_ms[i], profile_note(s, frame));
    }
    const bool moved = app.stats.cloth_uploaded;
    const StageState drawn = moved ? StageState::Runs : StageState::Skipped;
    row("normals", drawn, app.stats.times.normals_ms, moved ? "renderer" : "nothing moved");
    row("upload", drawn, app.stats.times.upload_ms, moved ? "positions and normals to the GPU" : "nothing moved");
    ImGui::EndTable();
    ImGui::Text("stages %.3f ms per frame (smoothed over ~10 frames)", total);
}

void help_section() {
    ImGui::TextUnformatted("Mouse");
    ImGui::BulletText("left-drag on empty space: orbit");
    ImGui::BulletText("right- or middle-drag, shift+left-drag: pan");
    ImGui::BulletText("shift+right-drag: cut the springs the stroke crosses");
    ImGui::BulletText("wheel: zoom");
    ImGui::BulletText("left-drag on the cloth: grab a particle");
    ImGui::BulletText("ctrl+click on the cloth: pin / unpin a particle");
    ImGui::BulletText("alt+left-drag on an object: move it (it pushes and carries the cloth)");
    ImGui::BulletText("drop a .toml file onto the window: open it");
    ImGui::BulletText("drop an .obj file: add it as an object under the cursor");
    ImGui::TextUnformatted("Keys");
    ImGui::BulletText("Space: pause / play      S: single step");
    ImGui::BulletText("R: reset the scene       W: wireframe");
    ImGui::BulletText("H: hide / show panel     F: frame the cloth");
    ImGui::BulletText("Home: reset the camera   F12: screenshot");
    ImGui::BulletText("F9: start / stop recording frames");
    ImGui::BulletText("Esc: quit");
}

}  // namespace

float panel_width(const AppState& app, float content_scale, float window_width) {
    if (!app.show_panel) return 0.0f;
    return std::min(app.panel_width * content_scale, kMaxPanelShare * window_width);
}

namespace {

// The message area: a fixed height at the bottom of the panel (it never pushes the widgets), newest last,
// scrolled to the newest, with a button to clear it.
void message_area(AppState& app, float height) {
    app.messages.expire();
    ImGui::BeginChild("messages", ImVec2(0.0f, height), true);
    if (app.messages.list.empty()) ImGui::TextDisabled("no messages");
    ImGui::PushTextWrapPos(0.0f);
    for (const Messages::Message& m : app.messages.list) {
        ImGui::TextColored(m.error ? ImVec4(1.0f, 0.45f, 0.4f, 1.0f) : ImVec4(0.6f, 0.9f, 0.6f, 1.0f), "%s",
                           m.text.c_str());
    }
    ImGui::PopTextWrapPos();
    if (ImGui::GetScrollY() >= ImGui::GetScrollMaxY()) ImGui::SetScrollHereY(1.0f);
    ImGui::EndChild();
    if (ImGui::SmallButton("Clear messages")) app.messages.clear();
}

// Bundled scenes, open a file, recent files, play / step / reset, time scale, save, record.
void scene_section(AppState& app, PanelRequests& requests) {
    const std::vector<std::string> names = bundled_scene_names();
    // The combo shows the scene's name, and for a scene from a file its file name (the full path in the
    // tooltip); its items are the bundled scenes.
    const bool from_file = is_scene_file(app.scene_source);
    const std::string shown =
        from_file ? app.scene.name + " (" + std::filesystem::path(app.scene_source).filename().string() + ")" : app.scene.name;
    if (ImGui::BeginCombo("scene", shown.c_str())) {
        for (const std::string& n : names) {
            if (ImGui::Selectable(n.c_str(), !from_file && n == app.scene_source)) requests.load = n;
        }
        ImGui::EndCombo();
    }
    if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("%s", from_file ? app.scene_source.c_str() : "a bundled scene; pick another here");
    }
    const bool dialog_open = app.dialogs.open();
    ImGui::BeginDisabled(dialog_open);
    if (ImGui::Button("Open file...")) requests.open_dialog = true;
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
        ImGui::SetTooltip("opens a .toml scene file (or drop one onto the window); a bad file is rejected and nothing changes");
    }
    ImGui::SameLine();
    ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x);
    if (ImGui::BeginCombo("##recent", "Recent", ImGuiComboFlags_HeightLarge)) {
        if (app.recent.files().empty()) ImGui::TextDisabled("no recent files");
        for (const std::string& f : app.recent.files()) {
            if (ImGui::Selectable(f.c_str())) requests.load = f;
        }
        ImGui::EndCombo();
    }
    ImGui::EndDisabled();
    if (ImGui::Button(app.paused ? "Play (Space)" : "Pause (Space)")) app.paused = !app.paused;
    ImGui::SameLine();
    if (ImGui::Button("Step (S)")) {
        app.paused = true;
        app.step_once = true;
    }
    ImGui::SameLine();
    if (ImGui::Button("Reset (R)")) requests.reset = true;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("back to the start of the scene as edited: pins, grid and settings kept");
    ImGui::SameLine();
    if (ImGui::Button("Revert")) requests.revert = true;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("back to the scene as loaded or last saved, dropping every edit");
    ImGui::SameLine();
    if (ImGui::Button(app.settling ? "Stop settling" : "Settle")) {
        if (app.settling) app.stop_settling();
        else app.settling.emplace();
    }
    if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("runs the cloth to rest as fast as it can: the dynamics with every velocity zeroed past each "
                          "peak of the kinetic energy (kinetic damping), and a damping of its own once the fall is over, "
                          "until the largest net force on a particle is under 1%% of its weight (docs/MATERIAL.md)");
    }
    if (app.settling) {
        const Residual& r = app.settling->residual();
        if (std::isfinite(r.value)) {
            ImGui::Text("settling: residual %.3g (to %.3g), %d resets%s, t = %.2f s", r.value,
                        app.settling->options().tolerance, app.settling->resets(),
                        app.settling->damping() ? ", damped" : "", app.sim.time());
        } else {
            ImGui::Text("settling: t = %.2f s", app.sim.time());
        }
    }
    ImGui::SliderFloat("time scale", &app.time_scale, 0.05f, 4.0f, "%.2fx",
                       ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("simulated seconds per wall-clock second");
    ImGui::BeginDisabled(dialog_open);
    if (ImGui::Button("Save scene as...")) requests.save_dialog = true;
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("writes the current settings as a scene file (atomically)");
    ImGui::EndDisabled();
    ImGui::SameLine();
    if (app.recording) {
        ImGui::PushStyleColor(ImGuiCol_Button, ImVec4(0.75f, 0.15f, 0.15f, 1.0f));
        if (ImGui::Button("Stop recording (F9)")) requests.record = true;
        ImGui::PopStyleColor();
        // Where the frames go, while they go there (a line that exists only while recording).
        ImGui::TextColored(ImVec4(1.0f, 0.45f, 0.4f, 1.0f), "REC %s/ %lld frames",
                           app.recording->folder.filename().c_str(), app.recording->frames);
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", app.recording->folder.c_str());
    } else {
        if (ImGui::Button("Record (F9)")) requests.record = true;
        if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip("writes every frame as a PNG into a new folder clothsim-recording-DATE-TIME, one step of "
                              "integration.dt per frame");
        }
    }
}

// The forces' fields; the wind's speed and heading beneath its vector, read from it.
void forces_section(Scene& edit, AppState& app) {
    fields_section(edit, app, "forces.");
    const glm::vec3 wind = edit.settings.forces.wind;
    const float speed = std::sqrt(wind.x * wind.x + wind.y * wind.y + wind.z * wind.z);
    if (speed > 0.0f) {
        ImGui::TextDisabled("wind %.3g m/s, heading %.0f deg from +x toward +z", speed,
                            std::atan2(wind.z, wind.x) * 57.29578f);
    } else {
        ImGui::TextDisabled("no wind");
    }
}

// The stability limit, where the current substep stands against it, and the auto choice (the stepper's).
void stability_lines(AppState& app) {
    bool auto_substeps = app.stepper.policy().auto_substeps;
    if (ImGui::Checkbox("auto substeps", &auto_substeps)) app.stepper.set_auto_substeps(auto_substeps);
    if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("choose substeps every frame so the substep stays at the safety fraction of the\n"
                          "critical substep (Gershgorin bound, docs/STABILITY.md)");
    }
    if (auto_substeps) {
        ImGui::SameLine();
        ImGui::SetNextItemWidth(ImGui::GetFontSize() * 7.0f);
        float safety = app.stepper.policy().safety;
        if (ImGui::SliderFloat("safety", &safety, 0.05f, 1.0f, "%.2f", ImGuiSliderFlags_AlwaysClamp)) app.stepper.set_safety(safety);
    }
    const StabilityLimit& limit = app.stepper.limit(app.sim);
    const IntegrationSettings& integration = app.sim.settings().integration;
    const double substep = app.sim.substep_length();
    if (limit.unconditionally_stable) {  // two lines, as below: nothing moves when the integrator changes
        ImGui::TextColored(ImVec4(0.6f, 0.9f, 0.6f, 1.0f), "no explicit step limit (%s)",
                           std::string(integrator_names()[static_cast<int>(integration.integrator)]).c_str());
        ImGui::Text("substep %.4g ms%s", 1e3 * substep, auto_substeps ? " (auto)" : "");
        return;
    }
    const double fraction = substep / limit.critical_substep;
    const ImVec4 colour = fraction < 0.7   ? ImVec4(0.6f, 0.9f, 0.6f, 1.0f)
                          : fraction < 1.0 ? ImVec4(1.0f, 0.85f, 0.3f, 1.0f)
                                           : ImVec4(1.0f, 0.4f, 0.35f, 1.0f);
    if (limit.bound != StabilityBound::Springs) {
        // The springs are implicit: a plane wave of them sets no limit (stability.hpp).
        ImGui::Text("critical substep %.4g ms (%s)", 1e3 * limit.critical_substep,
                    limit.bound == StabilityBound::Damping ? "damping: c h < 2"
                    : limit.bound == StabilityBound::SoftClips ? "soft clips" : "penalty contact");
    } else {
        ImGui::Text("critical substep %.4g ms (plane wave %.4g ms)", 1e3 * limit.critical_substep,
                    1e3 * limit.plane_wave_substep);
    }
    if (limit.at_strain_substep != limit.critical_substep) {
        // A stretch curve: the bound is its steepest tangent's; the cloth as it is now would allow more. Marked
        // on the line (SameLine: nothing below moves).
        ImGui::SameLine();
        ImGui::TextDisabled("(i)");
        if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip("%.4g ms at the strain the cloth has now: the stretch curve's steepest tangent\n"
                              "bounds the substep, so that it holds at any strain (docs/MATERIAL.md)",
                              1e3 * limit.at_strain_substep);
        }
    }
    ImGui::TextColored(colour, "substep %.4g ms = %.2f of critical%s", 1e3 * substep, fraction,
                       auto_substeps ? " (auto)" : (fraction >= 1.0 ? ": may blow up" : ""));
}

void integration_section(Scene& edit, AppState& app) {
    stability_lines(app);
    fields_section(edit, app, "integration.");
    fields_section(edit, app, "solver.");
    float budget_ms = static_cast<float>(1e3 * app.stepper.policy().frame_budget);
    if (ImGui::SliderFloat("frame budget (ms)", &budget_ms, 5.0f, 200.0f, "%.0f", ImGuiSliderFlags_AlwaysClamp)) {
        app.stepper.set_frame_budget(1e-3 * budget_ms);
    }
    if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("wall time a frame spends on physics before it starts no further step (one step always\n"
                          "runs); a simulation that needs more runs slower than real time instead of freezing the app");
    }
}

// A mesh collider's file, typed and confirmed with Enter: read at once (beside the scene file, else bundled);
// one that does not load keeps the mesh there was and says why.
bool mesh_file_row(Collider& collider, const ColliderField& f, AppState& app) {
    auto* mesh = std::get_if<MeshCollider>(&collider.shape);
    if (!mesh) return false;
    char buffer[512];
    std::snprintf(buffer, sizeof buffer, "%s", mesh->file.c_str());
    if (!ImGui::InputText("file", buffer, sizeof buffer, ImGuiInputTextFlags_EnterReturnsTrue)) {
        if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip("%s\n%s triangles; type another and press Enter to load it", std::string(f.help).c_str(),
                              mesh->mesh ? std::to_string(mesh->mesh->triangles().size()).c_str() : "no");
        }
        return false;
    }
    MeshCollider loaded = *mesh;
    loaded.file = buffer;
    try {
        load_collider_mesh(loaded, scene_file_directory(app.scene_source));
    } catch (const SceneError& e) {
        app.say(std::string("mesh not loaded: ") + e.what(), true);
        return false;
    }
    *mesh = std::move(loaded);
    return true;
}

// One collider's rows: its fields as drags (clamped to their range), each with its tooltip. Returns true when
// the user changed one.
bool collider_rows(Collider& collider, AppState& app) {
    bool changed = false;
    for (const ColliderField& f : collider_fields(collider)) {
        if (std::holds_alternative<std::string*>(f.ref)) {
            changed |= mesh_file_row(collider, f, app);
            continue;
        }
        std::string label(f.name);
        if (!f.unit.empty()) label += " (" + std::string(f.unit) + ")";
        const auto lo = static_cast<float>(f.min), hi = static_cast<float>(f.max);
        changed |= std::visit(Overloaded{
                                  [&](bool* v) { return ImGui::Checkbox(label.c_str(), v); },
                                  [&](float* v) {
                                      const float speed = std::max(std::fabs(*v) * 0.01f, 0.001f);
                                      return ImGui::DragFloat(label.c_str(), v, speed, lo, hi, "%.4g",
                                                              ImGuiSliderFlags_AlwaysClamp);
                                  },
                                  [&](glm::vec3* v) {
                                      const float speed = std::max(0.005f, 0.01f * std::max({std::fabs(v->x), std::fabs(v->y), std::fabs(v->z)}));
                                      return ImGui::DragFloat3(label.c_str(), &v->x, speed, lo, hi, "%.3g",
                                                               ImGuiSliderFlags_AlwaysClamp);
                                  },
                                  [&](auto*) { return false; },
                              },
                              f.ref);
        if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip("%s\nallowed: %s", std::string(f.help).c_str(), describe_allowed(f).c_str());
        }
    }
    return changed;
}

void colliders_section(Scene& edit, AppState& app) {
    // The list of shapes: each a tree node named by kind and place in the list, with its fields and a remove
    // button; an add combo below. Edits apply live (MassSpring::apply), as any setting.
    std::vector<Collider>& shapes = edit.settings.colliders.shapes;
    std::optional<std::size_t> removed;
    for (std::size_t i = 0; i < shapes.size(); ++i) {
        ImGui::PushID(static_cast<int>(i));
        const std::string title = std::to_string(i) + ": " + std::string(kind_name(shapes[i])) +
                                  (shapes[i].enabled ? "" : " (off)");
        const bool open = ImGui::TreeNodeEx("shape", ImGuiTreeNodeFlags_DefaultOpen, "%s", title.c_str());
        ImGui::SameLine();
        if (ImGui::SmallButton("remove")) removed = i;
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("remove this collider from the scene");
        if (open) {
            collider_rows(shapes[i], app);
            ImGui::TreePop();
        }
        ImGui::PopID();
    }
    if (removed) shapes.erase(shapes.begin() + static_cast<std::ptrdiff_t>(*removed));
    const auto names = collider_kind_names();
    std::string kinds;
    for (std::string_view name : names) kinds += (kinds.empty() ? "" : ", ") + std::string(name);
    if (ImGui::BeginCombo("add collider", kinds.c_str())) {
        for (std::size_t kind = 0; kind < names.size(); ++kind) {
            if (ImGui::Selectable(std::string(names[kind]).c_str())) shapes.push_back(default_collider(kind));
        }
        ImGui::EndCombo();
    }
    ImGui::Separator();
    fields_section(edit, app, "colliders.thickness");
    ImGui::Separator();
    ImGui::TextDisabled("contact model");
    fields_section(edit, app, "colliders.contact");  // the model and its stiffness
    const ColliderSettings& c = edit.settings.colliders;
    if (c.contact == ContactModel::Penalty && !(c.thickness > 0.0f)) {
        ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.3f, 1.0f), "penalty contact needs thickness > 0: no contact now");
    }
    ImGui::Separator();
    ImGui::TextDisabled("self-collision");
    fields_section(edit, app, "collision.");
    if (edit.settings.collision.self) {
        const double spacing = app.sim.self_collision_spacing();
        const float thickness = edit.settings.collision.self_thickness;
        if (thickness < spacing) {
            ImGui::TextDisabled("layers kept %.3g mm apart (the particle spacing)", 1e3 * spacing);
        }
    }
}

void view_section(AppState& app, PanelRequests& requests) {
    ImGui::Checkbox("wireframe (W)", &app.view.wireframe);
    int springs = static_cast<int>(app.view.springs);
    ImGui::Combo("springs", &springs, "hidden\0by kind\0by strain\0");
    app.view.springs = static_cast<SpringView>(springs);
    if (app.view.springs == SpringView::ByKind) {
        ImGui::TextColored(ImVec4(1.0f, 0.85f, 0.2f, 1.0f), "structural");
        ImGui::SameLine();
        ImGui::TextColored(ImVec4(0.2f, 0.85f, 1.0f, 1.0f), "shear");
        ImGui::SameLine();
        ImGui::TextColored(ImVec4(1.0f, 0.35f, 0.9f, 1.0f), "bending");
    }
    if (app.view.springs == SpringView::ByStrain) {
        ImGui::SliderFloat("strain range", &app.view.strain_range, 0.001f, 0.5f, "%.3f",
                       ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp);
        ImGui::TextDisabled("blue compressed, white at rest, red stretched");
    }
    ImGui::Checkbox("particles", &app.view.particles);
    ImGui::Checkbox("highlight pinned particles", &app.view.highlight_pins);
    ImGui::Checkbox("fabric texture", &app.view.texture);
    ImGui::Checkbox("shadows", &app.view.shadows);
    ImGui::Checkbox("vsync", &app.vsync);
    // The anti-aliasing the window got: chosen at launch (--samples), as a window's samples cannot change.
    if (app.display.samples > 0) {
        ImGui::TextDisabled("anti-aliasing: %dx MSAA", app.display.samples);
    } else {
        ImGui::TextDisabled(app.display.samples_auto_off ? "anti-aliasing: off (software renderer)" : "anti-aliasing: off");
    }
    if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("OpenGL renderer: %s\nSet at launch with --samples N (0 to 16); by default 4, or none on a "
                          "software renderer, which rasterises every sample on the CPU.",
                          app.display.renderer.c_str());
    }
    if (ImGui::Button("Frame cloth (F)")) requests.frame_camera = true;
    ImGui::SameLine();
    if (ImGui::Button("Reset camera (Home)")) requests.reset_camera = true;
}

void stats_section(const AppState& app) {
    const ImGuiIO& io = ImGui::GetIO();
    // This frame's wall time, in parts that add up: the physics, the drawing, and the rest (the buffer swap,
    // vsync's wait, input).
    const Stats& st = app.stats;
    ImGui::Text("%.0f FPS: frame %.1f ms (%lld substeps)", io.Framerate, st.frame_ms, st.substeps_last_frame);
    ImGui::Text("= simulation %.1f + render %.1f + swap, wait %.1f", st.sim_ms, st.render_ms,
                std::max(st.frame_ms - st.sim_ms - st.render_ms, 0.0f));
    if (app.sim.broken_springs() > 0) {  // torn or cut: as --json's broken_springs
        ImGui::Text("%zu particles, %zu springs (%zu broken), t = %.2f s", app.sim.particle_count(),
                    app.sim.spring_count(), app.sim.broken_springs(), app.sim.time());
    } else {
        ImGui::Text("%zu particles, %zu springs, t = %.2f s", app.sim.particle_count(), app.sim.spring_count(),
                    app.sim.time());
    }
    // The fast path runs position Verlet (the fast solver, or on a mesh cloth the element gather) and XPBD (its
    // grid form, or on a mesh cloth its coloured form); every other integrator uses the shared textbook force path.
    const bool fast = app.sim.last_step_fast();
    const bool wide = std::string_view(MassSpring::fast_kernel_name()) == "avx512";
    const char* form = !app.sim.topology().mesh                                       ? MassSpring::fast_kernel_name()
                       : app.sim.settings().integration.integrator == Integrator::Xpbd ? (wide ? "colours, avx512" : "colours")
                       : wide                                                          ? "element gather, avx512"
                                                                                       : "element gather";
    const double per_substep_us = app.stats.substeps_last_frame > 0
                                      ? 1000.0 * app.stats.sim_ms / double(app.stats.substeps_last_frame)
                                      : 0.0;
    if (fast) {
        ImGui::Text("solver: fast, %s, %d thread%s: %.1f us/substep", form, app.sim.solver_threads(),
                    app.sim.solver_threads() == 1 ? "" : "s", per_substep_us);
    } else {
        ImGui::Text("solver: textbook, 1 thread: %.1f us/substep", per_substep_us);
    }
    // Said only while the simulation cannot keep up with the time scale; a line kept in place (blank when it
    // keeps up) so nothing below it moves.
    if (!app.paused && app.stats.speed < 0.9f * app.time_scale) {
        // One step's ms this frame: over the budget, the physics is what cannot keep up; under it, the frames.
        const long long steps = app.stats.substeps_last_frame / std::max(app.sim.settings().integration.substeps, 1);
        const double step_ms = steps > 0 ? app.stats.sim_ms / double(steps) : 0.0;
        ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "running slow: %.2fx real time (%s)", app.stats.speed,
                           step_ms > 1e3 * app.stepper.policy().frame_budget ? "a step > frame budget" : "slow frames");
        if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip("simulated seconds per wall second over the last half second, against the time scale "
                              "%.2fx;\na step > frame budget: one step of physics takes longer than the frame budget "
                              "(Integration);\nslow frames: the drawing or the buffer swap takes the time",
                              app.time_scale);
        }
    } else {
        ImGui::TextUnformatted("");
    }
    // Accuracy hint: how much total energy moved over the plotted window. With no damping, no wind and no
    // contact it should stay put, and its drift measures the integrator's error at this step.
    const Integrator integrator = app.sim.settings().integration.integrator;
    ImGui::Text("integrator: %s%s", std::string(integrator_names()[static_cast<int>(integrator)]).c_str(),
                reports_solve(integrator)
                    ? (", " + std::string(integrator_info(integrator).solve_label) +
                       std::to_string(app.sim.last_solver_iterations()) + " iterations, residual " +
                       [&] {
                           char text[32];
                           std::snprintf(text, sizeof text, "%.2g", app.sim.last_solver_residual());
                           return std::string(text);
                       }())
                          .c_str()
                    : "");
    if (app.stats.total.size() > 1) {
        const History& e = app.stats.total;
        const float first = e.values[static_cast<std::size_t>(e.offset())];
        const float drift = (e.last() - first) / std::max(std::fabs(first), 1e-6f);
        const bool conservative = app.sim.settings().springs.damping == 0.0f &&
                                  app.sim.settings().forces.wind == glm::vec3(0.0f);
        ImGui::TextColored(conservative && std::fabs(drift) > 0.01f ? ImVec4(1.0f, 0.6f, 0.3f, 1.0f)
                                                                    : ImVec4(0.8f, 0.8f, 0.8f, 1.0f),
                           "energy drift over the plot: %+.3g%%%s", 100.0 * drift,
                           conservative ? " (error)" : "");
        if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip("relative change of total energy over the last %d frames; with no damping,\n"
                              "wind or contact it is integration error. docs/ACCURACY.md compares the\n"
                              "integrators' errors against run time.",
                              e.size());
        }
    }
    plot("kinetic", app.stats.kinetic, ImVec4(1.0f, 0.6f, 0.3f, 1.0f));
    plot("potential", app.stats.potential, ImVec4(0.4f, 0.7f, 1.0f, 1.0f));
    plot("total", app.stats.total, ImVec4(0.9f, 0.9f, 0.9f, 1.0f));
}

}  // namespace

PanelRequests draw_panel(AppState& app, float content_scale) {
    PanelRequests requests;
    const ImGuiViewport* viewport = ImGui::GetMainViewport();
    ImGui::SetNextWindowPos(viewport->WorkPos, ImGuiCond_Always);
    // The width is the user's: a drag of the panel's right edge sets it (kept between runs, app_settings.hpp), within
    // kMinPanelWidth and kMaxPanelShare of the window.
    const float max_width = std::max(kMaxPanelShare * viewport->WorkSize.x, kMinPanelWidth * content_scale);
    const float asked_width = panel_width(app, content_scale, viewport->WorkSize.x);
    ImGui::SetNextWindowSize(ImVec2(asked_width, viewport->WorkSize.y), ImGuiCond_Always);
    ImGui::SetNextWindowSizeConstraints(ImVec2(kMinPanelWidth * content_scale, viewport->WorkSize.y),
                                        ImVec2(max_width, viewport->WorkSize.y));
    ImGui::SetNextWindowBgAlpha(0.92f);
    ImGui::Begin("clothsim", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoCollapse);
    // Only a drag changes the width kept: a window too narrow for it shows it narrower, and keeps it.
    if (std::abs(ImGui::GetWindowWidth() - asked_width) > 0.5f) app.panel_width = ImGui::GetWindowWidth() / content_scale;
    // The settings scroll; the message area below them keeps its height, so nothing moves under the mouse.
    const float message_height = 5.5f * ImGui::GetTextLineHeightWithSpacing();
    ImGui::BeginChild("settings", ImVec2(0.0f, -(message_height + ImGui::GetFrameHeightWithSpacing() +
                                                ImGui::GetStyle().ItemSpacing.y)));
    // The labels' column: the longest label with its unit ("self friction (N/m)") and the reset button.
    ImGui::PushItemWidth(-ImGui::GetFontSize() * 14.0f);
    // The widgets edit a copy of the running scene. A settings change reaches the simulation through its one
    // call (MassSpring::apply); a cloth or pin change asks for a rebuild from the edited copy, which becomes
    // the document only when it builds.
    Scene edit = app.document();
    if (ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) scene_section(app, requests);
    bool cloth_changed = false;
    if (ImGui::CollapsingHeader("Cloth")) {
        ImGui::TextDisabled("grid, shape, mesh and pins: changes rebuild the cloth");
        if (app.sim.topology().mesh) {
            const std::string summary = cloth_mesh_summary(app.sim.topology(), app.sim.particle_count(),
                                                           app.stepper.limit(app.sim).critical_substep);
            ImGui::TextDisabled("%s", summary.c_str());
        }
        cloth_changed |= fields_section(edit, app, "cloth.");
        cloth_changed |= fields_section(edit, app, "pins");
    }
    FabricEdit fabric = FabricEdit::None;
    if (ImGui::CollapsingHeader("Springs", ImGuiTreeNodeFlags_DefaultOpen)) {
        fabric = fabric_section(edit, app);
        ImGui::Separator();
        fields_section(edit, app, "springs.");
    }
    if (ImGui::CollapsingHeader("Forces")) forces_section(edit, app);
    if (ImGui::CollapsingHeader("Integration", ImGuiTreeNodeFlags_DefaultOpen)) integration_section(edit, app);
    if (ImGui::CollapsingHeader("Colliders")) colliders_section(edit, app);
    if (fabric == FabricEdit::Live) put_fabric(app, edit);
    cloth_changed |= fabric == FabricEdit::Rebuild;
    app.sim.apply(edit.settings);
    if (cloth_changed) requests.rebuild = edit;
    if (ImGui::CollapsingHeader("View")) view_section(app, requests);
    if (ImGui::CollapsingHeader("Stats", ImGuiTreeNodeFlags_DefaultOpen)) stats_section(app);
    if (ImGui::CollapsingHeader("Profile", ImGuiTreeNodeFlags_DefaultOpen)) profile_section(app);
    if (ImGui::CollapsingHeader("Help")) help_section();
    ImGui::PopItemWidth();
    ImGui::EndChild();
    message_area(app, message_height);
    ImGui::End();
    return requests;
}

}  // namespace clothsim
