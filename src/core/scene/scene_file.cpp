// Scene files (TOML, read with toml++) and `--set key=value` overrides, both checked against the field
// table (scene_fields.cpp) so a bad value is reported with its source, line, field and allowed range.
#include "clothsim/scene.hpp"

#include "clothsim/data_dirs.hpp"
#include "clothsim/mesh_file.hpp"
#include "clothsim/material.hpp"
#include "clothsim/overloaded.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <type_traits>
#include <utility>

namespace clothsim {
namespace {

// Arrays, tables and floats are written here, not by toml++'s formatter: toml++ 3.3 sizes arrays and
// tables with static_cast<size_t>(log10(|x|)) per element, undefined behaviour for inf, nan, |x| < 1 and
// INT64_MIN (the values a bad scene file holds).
void show_into(std::string& out, const toml::node& node) {
    if (const auto* f = node.as_floating_point()) {
        const double v = f->get();
        if (std::isnan(v)) {
            out += "nan";
        } else if (std::isinf(v)) {
            out += v < 0 ? "-inf" : "inf";
        } else {
            char buffer[32];
            const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
            const std::string_view text(buffer, static_cast<std::size_t>(result.ptr - buffer));
            out += text;
            if (text.find_first_of(".e") == std::string_view::npos) out += ".0";  // a float, as TOML writes it
        }
    } else if (const auto* array = node.as_array()) {
        out += "[";
        for (std::size_t i = 0; i < array->size() && out.size() <= 60; ++i) {
            if (i) out += ", ";
            show_into(out, *array->get(i));
        }
        out += "]";
    } else if (const auto* table = node.as_table()) {
        out += "{";
        bool first = true;
        for (auto&& [key, value] : *table) {
            if (out.size() > 60) break;
            out += first ? " " : ", ";
            first = false;
            out += key.str();
            out += " = ";
            show_into(out, value);
        }
        out += " }";
    } else {
        std::ostringstream os;
        node.visit([&](const auto& n) { os << n; });
        out += os.str();
    }
}

std::string show(const toml::node& node) {
    std::string s;
    show_into(s, node);
    if (s.size() > 60) s = s.substr(0, 57) + "...";
    return s;
}

std::optional<double> number_of(const toml::node& node) {
    if (node.is_integer()) return static_cast<double>(node.as_integer()->get());
    if (node.is_floating_point()) return node.as_floating_point()->get();
    return std::nullopt;
}

// Reads `count` numbers from an array node; nullopt when it is not exactly that.
std::optional<std::vector<double>> numbers_of(const toml::node& node, std::size_t count) {
    const toml::array* array = node.as_array();
    if (!array || array->size() != count) return std::nullopt;
    std::vector<double> out;
    for (const toml::node& item : *array) {
        const auto v = number_of(item);
        if (!v) return std::nullopt;
        out.push_back(*v);
    }
    return out;
}

template <class Enum>
std::optional<Enum> enum_of(const toml::node& node, std::span<const std::string_view> names) {
    const auto text = node.value<std::string>();
    if (!text) return std::nullopt;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (names[i] == *text) return static_cast<Enum>(i);
    }
    return std::nullopt;
}

// Why a value was refused, when more can be said than "not allowed": the part at fault, and its node (for
// the line of an entry deep inside a multi-line list).
struct Rejection {
    std::string why;
    const toml::node* at = nullptr;
};

constexpr const char* kClipForm = "{ particle = [row, col], radius = R }, or on a mesh cloth { vertex = i } or { vertex = i, radius = R }";

// A clip's radius: a number in [0, kMaxPinRadius] m.
std::optional<float> pin_radius_of(const toml::node& node, const std::string& name, Rejection& rejection) {
    const auto v = number_of(node);
    if (!v || !std::isfinite(*v) || *v < 0.0 || *v > kMaxPinRadius) {
        rejection = {name + " = " + show(node) + " is " + (v ? "out of range" : "not a number") + "; allowed: " +
                         describe_pin_radius(),
                     &node};
        return std::nullopt;
    }
    return static_cast<float>(*v);
}

// [row, col]: two integers that fit in int (beyond int, a cast would wrap, 2^32 -> 0, and pin a particle the
// file never named; validate() checks that they lie in the grid).
std::optional<std::pair<int, int>> pin_cell_of(const toml::node& node, const std::string& name, Rejection& rejection) {
    const toml::array* pair = node.as_array();
    if (!pair || pair->size() != 2 || !(*pair)[0].is_integer() || !(*pair)[1].is_integer()) {
        rejection = {name + " = " + show(node) + " is not a particle; allowed: [row, col], two integers", &node};
        return std::nullopt;
    }
    const std::int64_t r = (*pair)[0].as_integer()->get(), c = (*pair)[1].as_integer()->get();
    constexpr std::int64_t lo = std::numeric_limits<int>::min(), hi = std::numeric_limits<int>::max();
    if (r < lo || r > hi || c < lo || c > hi) {
        rejection = {name + " = " + show(node) + " lies outside every grid; allowed: [row, col] inside the grid",
                     &node};
        return std::nullopt;
    }
    return std::pair{static_cast<int>(r), static_cast<int>(c)};
}

// One pin: [row, col], or a clip { particle = [row, col], radius = R }.
std::optional<Pin> pin_of(const toml::node& node, const std::string& name, Rejection& rejection) {
    const toml::table* table = node.as_table();
    if (!table) {
        if (!node.is_array()) {
            rejection = {name + " = " + show(node) + " is not a pin; allowed: [row, col] or " + kClipForm, &node};
            return std::nullopt;
        }
        const auto cell = pin_cell_of(node, name, rejection);
        if (!cell) return std::nullopt;
        return Pin{cell->first, cell->second, 0.0f};
    }
    std::optional<std::pair<int, int>> cell;
    float radius = 0.0f;
    int vertex = -1;
    for (auto&& [key, value] : *table) {
        if (key.str() == "particle") {
            cell = pin_cell_of(value, name + ".particle", rejection);
            if (!cell) return std::nullopt;
        } else if (key.str() == "vertex") {
            const std::optional<std::int64_t> i = value.value<std::int64_t>();
            if (!value.is_integer() || !i || *i < 0 || *i >= static_cast<std::int64_t>(kMaxParticles)) {
                rejection = {name + ".vertex = " + show(value) + " is not a vertex index; allowed: an integer in [0, " +
                                 std::to_string(kMaxParticles - 1) + "], counted from 0",
                             &value};
                return std::nullopt;
            }
            vertex = static_cast<int>(*i);
        } else if (key.str() == "radius") {
            const auto r = pin_radius_of(value, name + ".radius", rejection);
            if (!r) return std::nullopt;
            radius = *r;
        } else {
            rejection = {name + " has an unknown key '" + std::string(key.str()) + "'; allowed keys: particle, vertex, radius",
                         &value};
            return std::nullopt;
        }
    }
    if (cell && vertex >= 0) {
        rejection = {name + " = " + show(node) + " names both a particle and a vertex; allowed: one of them", &node};
        return std::nullopt;
    }
    if (vertex >= 0) return Pin{0, 0, radius, vertex};
    if (!cell) {
        rejection = {name + " = " + show(node) + " names no particle; allowed: " + kClipForm, &node};
        return std::nullopt;
    }
    return Pin{cell->first, cell->second, radius};
}

// A list of pins; `name` is how messages call the list ("pins", "pins.particles").
std::optional<std::vector<Pin>> pin_list_of(const toml::node& node, const std::string& name,
                                                Rejection& rejection) {
    const toml::array* array = node.as_array();
    if (!array) {
        rejection = {name + " = " + show(node) + " is not a list; allowed: a list of [row, col] or " + kClipForm,
                     &node};
        return std::nullopt;
    }
    std::vector<Pin> out;
    for (std::size_t i = 0; i < array->size(); ++i) {
        const auto pin = pin_of(*array->get(i), name + "[" + std::to_string(i) + "]", rejection);
        if (!pin) return std::nullopt;
        out.push_back(*pin);
    }
    return out;
}

std::optional<PinSpec> pins_of(const toml::node& node, Rejection& rejection) {
    PinSpec spec;
    if (auto preset = enum_of<PinPreset>(node, pin_preset_names())) {
        spec.preset = *preset;
        return spec;
    }
    if (node.is_array()) {
        auto list = pin_list_of(node, "pins", rejection);
        if (!list) return std::nullopt;
        spec.preset = PinPreset::None;
        spec.particles = *list;
        return spec;
    }
    if (const toml::table* table = node.as_table()) {
        spec.preset = PinPreset::None;
        for (auto&& [key, value] : *table) {
            if (key.str() == "preset") {
                auto preset = enum_of<PinPreset>(value, pin_preset_names());
                if (!preset) {
                    std::string names;
                    for (std::string_view n : pin_preset_names()) names += (names.empty() ? "" : ", ") + std::string(n);
                    rejection = {"pins.preset = " + show(value) + " is not a preset; allowed: " + names, &value};
                    return std::nullopt;
                }
                spec.preset = *preset;
            } else if (key.str() == "radius") {
                const auto radius = pin_radius_of(value, "pins.radius", rejection);
                if (!radius) return std::nullopt;
                spec.preset_radius = *radius;
            } else if (key.str() == "particles") {
                auto list = pin_list_of(value, "pins.particles", rejection);
                if (!list) return std::nullopt;
                spec.particles = *list;
            } else if (key.str() == "clip") {
                const auto clip = enum_of<ClipKind>(value, clip_kind_names());
                if (!clip) {
                    rejection = {"pins.clip = " + show(value) + " is not a clip kind; allowed: rigid, soft", &value};
                    return std::nullopt;
                }
                spec.clip = *clip;
            } else {
                rejection = {"pins has an unknown key '" + std::string(key.str()) +
                                 "'; allowed keys: preset, radius, particles, clip",
                             &value};
                return std::nullopt;
            }
        }
        return spec;
    }
    return std::nullopt;
}

// material.stretch_curve: a table { u = [[strain, factor], ...], v = [...] }, either key optional ({} is linear).
// The samples' order and ranges are validate()'s (stretch_samples_problem).
std::optional<StretchCurve> stretch_curve_of(const toml::node& node, Rejection& rejection) {
    const toml::table* table = node.as_table();
    if (!table) return std::nullopt;
    StretchCurve curve;
    for (auto&& [key, value] : *table) {
        const std::string name = "material.stretch_curve." + std::string(key.str());
        std::vector<StretchSample>* samples = key.str() == "u" ? &curve.u : key.str() == "v" ? &curve.v : nullptr;
        if (!samples) {
            rejection = {"material.stretch_curve has an unknown key '" + std::string(key.str()) + "'; allowed keys: u, v",
                         &value};
            return std::nullopt;
        }
        const toml::array* array = value.as_array();
        if (!array) {
            rejection = {name + " = " + show(value) + " is not a list; allowed: a list of [strain, factor]", &value};
            return std::nullopt;
        }
        for (std::size_t i = 0; i < array->size(); ++i) {
            const auto pair = numbers_of(*array->get(i), 2);
            if (!pair || !std::isfinite((*pair)[0]) || !std::isfinite((*pair)[1])) {
                rejection = {name + "[" + std::to_string(i) + "] = " + show(*array->get(i)) +
                                 " is not a sample; allowed: [strain, factor], two numbers",
                             array->get(i)};
                return std::nullopt;
            }
            samples->push_back({static_cast<float>((*pair)[0]), static_cast<float>((*pair)[1])});
        }
    }
    return curve;
}

// Sets one field from a TOML node. Returns false (and leaves the scene alone) when the node's type or
// value is not allowed, saying why in `rejection` where it can; validate() checks cross-field rules afterwards.
bool assign_to(FieldRef target_ref, double min, double max, const toml::node& node, Rejection& rejection) {
    auto in_range = [&](double v) { return std::isfinite(v) && v >= min && v <= max; };
    return std::visit(
        Overloaded{
            [&](int* target) {
                if (!node.is_integer()) return false;
                const auto v = node.as_integer()->get();
                if (!in_range(static_cast<double>(v))) return false;
                *target = static_cast<int>(v);
                return true;
            },
            [&](float* target) {
                const auto v = number_of(node);
                if (!v || !in_range(*v)) return false;
                *target = static_cast<float>(*v);
                return true;
            },
            [&](bool* target) {
                if (!node.is_boolean()) return false;
                *target = node.as_boolean()->get();
                return true;
            },
            [&](glm::vec2* target) {
                if (const auto v = number_of(node)) {
                    if (!in_range(*v)) return false;
                    *target = glm::vec2(static_cast<float>(*v));
                    return true;
                }
                const auto v = numbers_of(node, 2);
                if (!v || !std::all_of(v->begin(), v->end(), in_range)) return false;
                *target = glm::vec2((*v)[0], (*v)[1]);
                return true;
            },
            [&](glm::vec3* target) {
                const auto v = numbers_of(node, 3);
                if (!v || !std::all_of(v->begin(), v->end(), in_range)) return false;
                *target = glm::vec3((*v)[0], (*v)[1], (*v)[2]);
                return true;
            },
            [&](std::string* target) {
                const auto v = node.value<std::string>();
                if (!v || !node.is_string()) return false;
                *target = *v;
                return true;
            },
            [&](PinSpec* target) {
                const auto v = pins_of(node, rejection);
                if (!v) return false;
                *target = *v;
                return true;
            },
            [&](StretchCurve* target) {
                const auto v = stretch_curve_of(node, rejection);
                if (!v) return false;
                *target = *v;
                return true;
            },
            [&]<class Enum>(Enum* target) requires std::is_enum_v<Enum> {
                const auto v = enum_of<Enum>(node, names_of(target));
                if (!v) return false;
                *target = *v;
                return true;
            },
        },
        target_ref);
}

bool assign(Scene& scene, const FieldInfo& field, const toml::node& node, Rejection& rejection) {
    return assign_to(field.ref(scene), field.min, field.max, node, rejection);
}

// Well-formed UTF-8 (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF), as TOML requires.
bool valid_utf8(std::string_view text) {
    std::size_t i = 0;
    while (i < text.size()) {
        const auto b = static_cast<unsigned char>(text[i]);
        std::size_t length = 0;
        std::uint32_t code = 0, least = 0;
        if (b < 0x80) { ++i; continue; }
        if ((b & 0xE0) == 0xC0) { length = 2; code = b & 0x1F; least = 0x80; }
        else if ((b & 0xF0) == 0xE0) { length = 3; code = b & 0x0F; least = 0x800; }
        else if ((b & 0xF8) == 0xF0) { length = 4; code = b & 0x07; least = 0x10000; }
        else return false;
        if (i + length > text.size()) return false;
        for (std::size_t k = 1; k < length; ++k) {
            const auto c = static_cast<unsigned char>(text[i + k]);
            if ((c & 0xC0) != 0x80) return false;
            code = (code << 6) | (c & 0x3F);
        }
        if (code < least || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return false;
        i += length;
    }
    return true;
}

std::string where(std::string_view source, const toml::node& node) {
    const auto& begin = node.source().begin;
    std::string s(source);
    if (begin.line > 0) s += ":" + std::to_string(begin.line) + ":" + std::to_string(begin.column);
    return s;
}

bool is_section(std::string_view prefix) {
    const std::string dotted = std::string(prefix) + ".";
    for (const FieldInfo& f : scene_fields()) {
        if (f.name.starts_with(dotted)) return true;
    }
    return false;
}

std::string fields_in(std::string_view section) {
    std::vector<std::string> names;
    const std::string dotted = section.empty() ? "" : std::string(section) + ".";
    for (const FieldInfo& f : scene_fields()) {
        if (!f.name.starts_with(dotted)) continue;
        std::string_view rest = f.name.substr(dotted.size());
        std::string first(rest.substr(0, rest.find('.')));
        if (std::find(names.begin(), names.end(), first) == names.end()) names.push_back(first);
    }
    std::string list;
    for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
    return list;
}

std::string kind_list() {
    std::string list;
    for (std::string_view k : collider_kind_names()) list += (list.empty() ? "" : ", ") + std::string(k);
    return list;
}

std::string collider_field_names(Collider& collider) {
    std::string list;
    for (const ColliderField& f : collider_fields(collider)) list += (list.empty() ? "" : ", ") + std::string(f.name);
    return list;
}

void load_collider_fields(Collider& collider, const toml::table& table, const std::string& name, std::string_view source);

// The fields of one collider from a table (a [[colliders.shapes]] entry or a first-form section), `name` its
// dotted name in messages, and a mesh's triangles. `kind` is read by the caller.
void load_collider(Collider& collider, const toml::table& table, const std::string& name, std::string_view source) {
    load_collider_fields(collider, table, name, source);
    // A mesh's file, beside the scene file (source names it) or bundled.
    if (auto* mesh = std::get_if<MeshCollider>(&collider.shape)) {
        const toml::node* file = table.get("file");
        const std::string at = file ? where(source, *file) : std::string(source);
        if (!file) throw SceneError(at + ": " + name + ".file is missing; allowed: the path of a Wavefront OBJ file");
        try {
            load_collider_mesh(*mesh, scene_file_directory(source));
        } catch (const SceneError& e) {
            throw SceneError(at + ": " + name + ".file = \"" + mesh->file + "\": " + e.what());
        }
    }
}

void load_collider_fields(Collider& collider, const toml::table& table, const std::string& name, std::string_view source) {
    for (auto&& [key, node] : table) {
        if (key.str() == "kind") continue;
        const std::string field_name = name + "." + std::string(key.str());
        const auto rows = collider_fields(collider);
        const std::string_view wanted = key.str();  // a name, not the binding: clang 14 cannot capture those
        const auto row = std::find_if(rows.begin(), rows.end(), [&](const ColliderField& f) { return f.name == wanted; });
        if (row == rows.end()) {
            throw SceneError(where(source, node) + ": unknown field '" + field_name + "'; known fields of a " +
                             std::string(kind_name(collider)) + ": " + collider_field_names(collider));
        }
        if (Rejection rejection; !assign_to(row->ref, row->min, row->max, node, rejection)) {
            throw SceneError(where(source, node) + ": " + field_name + " = " + show(node) +
                             " is not allowed; allowed: " + describe_allowed(*row));
        }
    }
}

// colliders.shapes: an array of tables ([[colliders.shapes]]), each with a `kind`. It replaces the list (the
// default ground included): the scene holds exactly the shapes it names.
void load_shapes(Scene& scene, const toml::node& node, std::string_view source) {
    const toml::array* array = node.as_array();
    if (!array || !array->is_array_of_tables()) {
        throw SceneError(where(source, node) + ": colliders.shapes is a list of tables ([[colliders.shapes]] entries, "
                                               "each with kind = " + kind_list() + ")");
    }
    std::vector<Collider> shapes;
    for (std::size_t i = 0; i < array->size(); ++i) {
        const toml::table& entry = *array->get(i)->as_table();
        const std::string name = "colliders.shapes[" + std::to_string(i) + "]";
        const auto kind = entry["kind"].value<std::string>();
        const int index = kind ? find_collider_kind(*kind) : -1;
        if (index < 0) {
            const toml::node& at = entry.contains("kind") ? *entry.get("kind") : static_cast<const toml::node&>(entry);
            throw SceneError(where(source, at) + ": " + name + ".kind " +
                             (kind ? "= \"" + *kind + "\" is not a collider kind" : std::string("is missing")) +
                             "; allowed: one of " + kind_list());
        }
        shapes.push_back(default_collider(static_cast<std::size_t>(index)));
        load_collider(shapes.back(), entry, name, source);
    }
    scene.settings.colliders.shapes = std::move(shapes);
}

void load_table(Scene& scene, const toml::table& table, const std::string& prefix, std::string_view source) {
    if (prefix == "colliders") {
        // The list first: the first form's sections then address its colliders (first_form_collider).
        if (const toml::node* shapes = table.get("shapes")) load_shapes(scene, *shapes, source);
    }
    for (auto&& [key, node] : table) {
        const std::string name = prefix.empty() ? std::string(key.str()) : prefix + "." + std::string(key.str());
        if (prefix == "colliders" && key.str() == "shapes") continue;
        if (prefix == "colliders" && std::find(kFirstFormSections.begin(), kFirstFormSections.end(), key.str()) !=
                                         kFirstFormSections.end()) {
            const toml::table* sub = node.as_table();
            if (!sub) {
                throw SceneError(where(source, node) + ": " + name + " is a section, not a value; its fields: " +
                                 collider_field_names(first_form_collider(scene.settings.colliders, key.str())));
            }
            load_collider(first_form_collider(scene.settings.colliders, key.str()), *sub, name, source);
            continue;
        }
        if (const FieldInfo* field = find_field(name)) {
            if (Rejection rejection; !assign(scene, *field, node, rejection)) {
                throw SceneError(where(source, rejection.at ? *rejection.at : node) + ": " + name + " = " + show(node) +
                                 " is not allowed" +
                                 (rejection.why.empty() ? "; allowed: " + describe_allowed(*field)
                                                        : ": " + rejection.why));
            }
            note_field_set(scene, name);
            if (name == "cloth.mesh") {
                try {
                    load_cloth_mesh(scene.cloth, scene_file_directory(source));
                } catch (const SceneError& e) {
                    throw SceneError(where(source, node) + ": cloth.mesh = \"" + scene.cloth.mesh + "\": " + e.what());
                }
            }
        } else if (is_section(name)) {
            const toml::table* sub = node.as_table();
            if (!sub) {
                throw SceneError(where(source, node) + ": " + name + " is a section, not a value; its fields: " +
                                 fields_in(name));
            }
            load_table(scene, *sub, name, source);
        } else {
            throw SceneError(where(source, node) + ": unknown field '" + name + "'; known " +
                             (prefix.empty() ? std::string("top-level names") : "fields of [" + prefix + "]") + ": " +
                             fields_in(prefix) +
                             (prefix == "colliders" ? ", shapes, sphere, cube, cylinder, ground" : ""));
        }
    }
}

}  // namespace

Scene parse_scene(std::string_view toml_text, std::string_view source_name) {
    toml::table table;
    try {
        table = toml::parse(toml_text, source_name);
    } catch (const toml::parse_error& e) {
        const auto& begin = e.source().begin;
        throw SceneError(std::string(source_name) + ":" + std::to_string(begin.line) + ":" +
                         std::to_string(begin.column) + ": TOML syntax error: " + std::string(e.description()));
    }
    Scene scene;
    load_table(scene, table, "", source_name);
    // A file is not read in order: material.enabled = false beside another material field says two things.
    if (const toml::table* m = table["material"].as_table(); m && (*m)["enabled"].value_or(true) == false) {
        for (auto&& [key, node] : *m) {
            if (key.str() == "enabled") continue;
            throw SceneError(where(source_name, node) + ": material.enabled = false and material." +
                             std::string(key.str()) + " both set; allowed: either [material] with enabled = true " +
                             "(or without enabled), or enabled = false alone");
        }
    }
    try {
        validate(scene);
        derive_springs(scene);
    } catch (const SceneError& e) {
        // Cross-field messages start with the field they blame ("pins: ...", "cloth.u_axis and ..."): point
        // at that field's line when the file sets it.
        const std::string message = e.what();
        const std::string field = message.substr(0, message.find_first_of(" :"));
        const toml::node_view<const toml::node> node = std::as_const(table).at_path(field);
        throw SceneError((node ? where(source_name, *node.node()) : std::string(source_name)) + ": " + message);
    }
    return scene;
}

Scene load_scene_file(const std::filesystem::path& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        throw SceneError("cannot read scene file '" + path.string() + "': it is a directory");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw SceneError("cannot read scene file '" + path.string() + "': " + std::strerror(errno));
    }
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw SceneError("cannot read scene file '" + path.string() + "'");
    return parse_scene(text.str(), path.string());
}

std::filesystem::path scene_directory() {
    return data_directory("CLOTHSIM_SCENES", "scenes");
}

std::vector<std::string> bundled_scene_names() {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(scene_directory(), ec)) {
        if (entry.path().extension() == ".toml") names.push_back(entry.path().stem().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

bool is_scene_file(std::string_view name_or_path) {
    return name_or_path.find('/') != std::string_view::npos || std::filesystem::path(name_or_path).extension() == ".toml";
}

Scene load_scene(std::string_view name_or_path) {
    if (is_scene_file(name_or_path)) return load_scene_file(std::filesystem::path(name_or_path));
    const std::filesystem::path bundled = scene_directory() / (std::string(name_or_path) + ".toml");
    if (std::filesystem::exists(bundled)) return load_scene_file(bundled);
    std::string names;
    for (const std::string& n : bundled_scene_names()) names += (names.empty() ? "" : ", ") + n;
    throw SceneError("unknown scene '" + std::string(name_or_path) + "'; bundled scenes: " +
                     (names.empty() ? "(none found in " + scene_directory().string() + ")" : names) +
                     "; or give the path of a .toml file");
}

void apply_override(Scene& scene, std::string_view assignment) {
    const std::string source = "--set " + std::string(assignment);
    const auto eq = assignment.find('=');
    if (eq == std::string_view::npos || eq == 0) {
        throw SceneError(source + ": expected key=value, e.g. --set cloth.rows=64");
    }
    const std::string key(assignment.substr(0, eq));
    const std::string text(assignment.substr(eq + 1));
    // One --set is one field: a line break would let "rows=8\ncols=9" pass as a TOML document and drop the rest.
    if (text.find_first_of("\r\n") != std::string::npos) {
        throw SceneError(source + ": the value spans lines; give one field per --set");
    }
    // A collider's field: colliders.shapes.N.field (N from 0, in the list's order) or a first-form name
    // (colliders.sphere.radius: the first sphere, added switched off when there is none).
    Scene candidate = scene;
    std::optional<ColliderField> collider_field;
    Collider* edited = nullptr;  // the collider collider_field belongs to
    if (key.starts_with("colliders.")) {
        const std::string rest = key.substr(std::string_view("colliders.").size());
        const auto dot = rest.find('.');
        const std::string head = rest.substr(0, dot), tail = dot == std::string::npos ? "" : rest.substr(dot + 1);
        Collider* collider = nullptr;
        std::string field_name = tail;
        std::vector<Collider>& list = candidate.settings.colliders.shapes;
        if (head == "shapes") {
            const auto dot2 = tail.find('.');
            const std::string index_text = tail.substr(0, dot2);
            field_name = dot2 == std::string::npos ? "" : tail.substr(dot2 + 1);
            std::size_t index = 0;
            const auto parsed_index = std::from_chars(index_text.data(), index_text.data() + index_text.size(), index);
            if (parsed_index.ec != std::errc() || parsed_index.ptr != index_text.data() + index_text.size() ||
                index >= list.size()) {
                throw SceneError(source + ": " + key + " names no collider; allowed: colliders.shapes.N.<field> with N in [0, " +
                                 std::to_string(list.size()) + ") (the scene has " + std::to_string(list.size()) +
                                 (list.size() == 1 ? " collider)" : " colliders)"));
            }
            collider = &list[index];
        } else if (std::find(kFirstFormSections.begin(), kFirstFormSections.end(), head) != kFirstFormSections.end()) {
            collider = &first_form_collider(candidate.settings.colliders, head);
        }
        if (collider) {
            for (const ColliderField& f : collider_fields(*collider)) {
                if (f.name == field_name) collider_field = f, edited = collider;
            }
            if (!collider_field) {
                throw SceneError(source + ": unknown field '" + key + "'; known fields of a " +
                                 std::string(kind_name(*collider)) + ": " + collider_field_names(*collider));
            }
        }
    }
    const FieldInfo* field = collider_field ? nullptr : find_field(key);
    if (!field && !collider_field) {
        throw SceneError(source + ": unknown field '" + key + "'; fields: " + [] {
            std::string all;
            for (const FieldInfo& f : scene_fields()) all += (all.empty() ? "" : ", ") + std::string(f.name);
            return all + ", colliders.shapes.N.<field>, colliders.sphere|cube|cylinder|ground.<field>";
        }());
    }
    const std::string allowed = field ? describe_allowed(*field) : describe_allowed(*collider_field);
    // The value is TOML when it parses as one; otherwise it is taken as a bare string (top-row, uniform).
    std::optional<toml::table> parsed;
    try {
        parsed = toml::parse("value = " + text);
    } catch (const toml::parse_error&) {
    }
    // A bare word is stored as it is and written back by to_toml(): it must be text a scene file can hold.
    if (!parsed && !valid_utf8(text)) {
        throw SceneError(source + ": the value is not valid UTF-8; allowed: " + allowed);
    }
    const toml::value<std::string> bare(text);
    const toml::node& node = parsed && parsed->contains("value") ? *parsed->get("value")
                                                                    : static_cast<const toml::node&>(bare);
    Rejection rejection;
    const bool assigned = field ? assign(candidate, *field, node, rejection)
                                : assign_to(collider_field->ref, collider_field->min, collider_field->max, node, rejection);
    if (!assigned) {
        throw SceneError(source + ": " + key + " = " + show(node) + " is not allowed" +
                         (rejection.why.empty() ? "; allowed: " + allowed : ": " + rejection.why));
    }
    if (field) note_field_set(candidate, key);
    if (field && field->name == "cloth.mesh") {
        try {
            load_cloth_mesh(candidate.cloth, {});
        } catch (const SceneError& e) {
            throw SceneError(source + ": " + e.what());
        }
    }
    // A mesh collider given another file reads it (relative to the working directory, then bundled).
    if (auto* mesh = edited ? std::get_if<MeshCollider>(&edited->shape) : nullptr; mesh && collider_field->name == "file") {
        try {
            load_collider_mesh(*mesh, {});
        } catch (const SceneError& e) {
            throw SceneError(source + ": " + e.what());
        }
    }
    try {
        validate(candidate);
        derive_springs(candidate);
    } catch (const SceneError& e) {
        throw SceneError(source + ": " + e.what());
    }
    scene = std::move(candidate);
}

std::string to_toml(const Scene& scene) {
    std::string out = "# clothsim scene (fields, units and ranges: docs/SCENE_FILES.md)\n";
    if (scene.material.enabled && !scene.cloth.is_mesh() && scene.cloth.rows > 1 && scene.cloth.cols > 1) {
        if (const std::string note = spring_constants(scene.cloth, scene.material).note; !note.empty()) {
            out += "# material: " + note + "\n";
        }
    }
    // In the material form the per-spring fields are derived: shown as comments, not read back.
    auto line = [&](const FieldInfo& f, std::string_view key) -> std::string {
        const std::string text = std::string(key) + " = " + format_value(scene, f);
        if (field_is_written(scene, f.name)) return text + "\n";
        if (!f.name.starts_with("material.")) {
            return "# " + text + "  (derived from [material] on this " + (scene.cloth.is_mesh() ? "mesh" : "grid") + ")\n";
        }
        return "";
    };
    for (const FieldInfo& f : scene_fields()) {
        if (f.name.find('.') == std::string_view::npos) out += line(f, f.name);
    }
    std::string section;
    for (const FieldInfo& f : scene_fields()) {
        const auto dot = f.name.rfind('.');
        if (dot == std::string_view::npos) continue;
        const std::string text = line(f, f.name.substr(dot + 1));
        if (text.empty()) continue;
        const std::string s(f.name.substr(0, dot));
        if (s != section) {
            section = s;
            out += "\n[" + section + "]\n";
        }
        out += text;
    }
    // The colliders, one [[colliders.shapes]] entry each, every field written (the motion only for one that
    // moves: a still object's entry reads as before).
    for (Collider collider : scene.settings.colliders.shapes) {
        out += "\n[[colliders.shapes]]\nkind = \"" + std::string(kind_name(collider)) + "\"\n";
        for (const ColliderField& f : collider_fields(collider)) {
            if ((f.name == "velocity" || f.name == "spin") && !collider.motion.moves()) continue;
            out += std::string(f.name) + " = " + format_value(f) + "\n";
        }
    }
    return out;
}

}  // namespace clothsim
