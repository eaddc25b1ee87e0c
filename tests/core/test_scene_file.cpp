// Scene files, --set overrides, the field table and pins: every bundled scene loads and runs, every bad
// input is rejected with a message naming its source, line, field and allowed values, and nothing is
// ever half-applied.
#include "clothsim/overloaded.hpp"
#include "clothsim/material.hpp"
#include "clothsim/scene.hpp"

#include "per_spring_scenes.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <variant>
#include <vector>

using Catch::Contains;
using clothsim::SceneError;

namespace {

const std::filesystem::path kData = CLOTHSIM_TEST_DATA;

// The message of the SceneError that parse_scene(text, "test.toml") throws.
std::string parse_error(const std::string& text) {
    try {
        clothsim::parse_scene(text, "test.toml");
    } catch (const SceneError& e) {
        return e.what();
    }
    return "(no SceneError thrown)";
}

std::string load_error(const std::filesystem::path& path) {
    try {
        clothsim::load_scene_file(path);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "(no SceneError thrown)";
}

std::string override_error(clothsim::Scene& scene, const std::string& assignment) {
    try {
        clothsim::apply_override(scene, assignment);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "(no SceneError thrown)";
}

std::string allowed(std::string_view field) {
    const clothsim::FieldInfo* f = clothsim::find_field(field);
    REQUIRE(f != nullptr);
    return clothsim::describe_allowed(*f);
}

// The same for a collider's field, by its first-form name: allowed_collider("cylinder", "radius") for
// colliders.cylinder.radius (collider fields are rows of their kind, not entries of the field table).
std::string allowed_collider(std::string_view kind, std::string_view field) {
    const int k = clothsim::find_collider_kind(kind);
    REQUIRE(k >= 0);
    for (const clothsim::ColliderField& f : clothsim::collider_fields_of_kind(static_cast<std::size_t>(k))) {
        if (f.name == field) return clothsim::describe_allowed(f);
    }
    FAIL("kind " << kind << " has no field " << field);
    return {};
}

// Shortest decimal text of a double that reads back to it.
std::string shortest(double v) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
    return std::string(buffer, result.ptr);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Bundled scenes
// ---------------------------------------------------------------------------------------------------------

TEST_CASE("scene: the bundled scene list is exactly the nineteen shipped scenes") {
    const std::vector<std::string> expected = {"cape",         "chair-drape", "curtain",     "cusick",
                                               "drape-cube",   "drape-sphere", "falling",    "flag",
                                               "fold",         "hanging",     "mannequin-drape", "moving-ball",
                                               "pile",         "skirt",       "stiff-drape", "stiff-hanging",
                                               "tabard",       "tablecloth",  "tear"};
    REQUIRE(clothsim::bundled_scene_names() == expected);
}

TEST_CASE("scene: every bundled scene loads, builds and stays finite for 2 simulated seconds (0.5 s sanitized)") {
    const std::vector<std::string> names = clothsim::bundled_scene_names();
    REQUIRE(names.size() == 19);
    for (const std::string& name : names) {
        INFO("scene " << name);
        // The costly scenes run the 2 s on a coarser grid (tests/support.hpp), and one step at their own size.
        if (clothsim::test::costly_scene(name)) {
            const clothsim::Scene shipped = clothsim::load_scene(name);
            clothsim::MassSpring full = clothsim::build_simulation(shipped);
            CHECK(full.particle_count() == static_cast<std::size_t>(shipped.cloth.rows) * shipped.cloth.cols);
            full.run_steps(1);
            CHECK(full.all_finite());
        }
        const clothsim::Scene scene = clothsim::test::scene_for_loops(name);
        CHECK(scene.name == name);
        CHECK_FALSE(scene.description.empty());
        clothsim::MassSpring sim = clothsim::build_simulation(scene);
        CHECK(sim.particle_count() == (scene.cloth.is_mesh() ? scene.cloth.mesh_data->vertices().size()
                                                             : static_cast<std::size_t>(scene.cloth.rows) * scene.cloth.cols));
        CHECK(sim.spring_count() > 0);
        const double dt = scene.settings.integration.dt;
        const long long steps = std::llround(2.0 / dt);
        CHECK(steps == 120);
        sim.run_steps(steps / clothsim::test::kLoopShare);
        CHECK(sim.time() == Approx(2.0 / clothsim::test::kLoopShare).margin(1e-3));
        CHECK(sim.all_finite());
        const clothsim::Energy e = sim.energy();
        CHECK(std::isfinite(e.kinetic));
        CHECK(std::isfinite(e.potential()));
        CHECK(std::isfinite(e.total()));
    }
}

TEST_CASE("scene: a bundled scene loads the values written in its file") {
    const clothsim::Scene s = clothsim::load_scene("flag");
    CHECK(s.cloth.rows == 24);
    CHECK(s.cloth.cols == 36);
    CHECK(s.cloth.size.x == 1.5f);
    CHECK(s.cloth.size.y == 1.0f);
    CHECK(s.pins.preset == clothsim::PinPreset::LeftEdge);
    CHECK(s.pins.particles.empty());
    CHECK(s.settings.forces.wind.x == 8.0f);
    CHECK(s.settings.forces.wind_model == clothsim::WindModel::Triangles);
    CHECK(s.settings.integration.substeps == 145);
    // Its fabric is a preset: the material fields are the preset's, and the mass is derived from its density.
    const clothsim::MaterialPreset* polyester = clothsim::find_material_preset("polyester-tropical");
    REQUIRE(polyester);
    CHECK(s.material.enabled);
    CHECK(s.material.preset == "polyester-tropical");
    CHECK(s.notes.empty());
    CHECK(s.material.density == polyester->density);
    CHECK(s.material.stretch == polyester->stretch);
    CHECK(s.per_spring_fields == 0);
    CHECK(s.cloth.mass == Approx(polyester->density * 1.5f * 1.0f));
    // A field a file leaves out keeps its default.
    CHECK(s.settings.colliders.thickness == clothsim::ColliderSettings{}.thickness);
}

TEST_CASE("scene: an unknown bundled scene name lists the bundled scenes") {
    std::string message;
    try {
        clothsim::load_scene("no-such-scene");
    } catch (const SceneError& e) {
        message = e.what();
    }
    CHECK_THAT(message, Contains("unknown scene 'no-such-scene'"));
    for (const std::string& name : clothsim::bundled_scene_names()) CHECK_THAT(message, Contains(name));
}

// ---------------------------------------------------------------------------------------------------------
// Malformed scene text
// ---------------------------------------------------------------------------------------------------------

TEST_CASE("scene file: a TOML syntax error names the file, the line and says so") {
    const std::string msg = parse_error("name = \"x\"\n[cloth]\nrows = = 3\n");
    CHECK_THAT(msg, Contains("test.toml:3:"));
    CHECK_THAT(msg, Contains("TOML syntax error"));
}

TEST_CASE("scene file: an out-of-range value names file, line, field, value and range") {
    const std::string msg = parse_error("name = \"x\"\n\n[cloth]\nrows = -3\n");
    CHECK_THAT(msg, Contains("test.toml:4:"));
    CHECK_THAT(msg, Contains("cloth.rows"));
    CHECK_THAT(msg, Contains("-3"));
    CHECK_THAT(msg, Contains("[1, 2048]"));
    CHECK_THAT(msg, Contains(allowed("cloth.rows")));

    const std::string too_big = parse_error("[integration]\ndt = 5.0\n");
    CHECK_THAT(too_big, Contains("test.toml:2:"));
    CHECK_THAT(too_big, Contains("integration.dt"));
    CHECK_THAT(too_big, Contains("5.0"));
    CHECK_THAT(too_big, Contains(allowed("integration.dt")));
    CHECK_THAT(too_big, Contains(" s"));  // the unit

    const std::string vec = parse_error("[forces]\ngravity = [0.0, -1e9, 0.0]\n");
    CHECK_THAT(vec, Contains("test.toml:2:"));
    CHECK_THAT(vec, Contains("forces.gravity"));
    CHECK_THAT(vec, Contains(allowed("forces.gravity")));
}

TEST_CASE("scene file: a value of the wrong type names file, line, field and allowed values") {
    const std::string msg = parse_error("[cloth]\nrows = 4\nmass = \"heavy\"\n");
    CHECK_THAT(msg, Contains("test.toml:3:"));
    CHECK_THAT(msg, Contains("cloth.mass"));
    CHECK_THAT(msg, Contains("heavy"));
    CHECK_THAT(msg, Contains(allowed("cloth.mass")));
    CHECK_THAT(msg, Contains("kg"));

    const std::string int_as_float = parse_error("[cloth]\nrows = 4.5\n");
    CHECK_THAT(int_as_float, Contains("test.toml:2:"));
    CHECK_THAT(int_as_float, Contains("cloth.rows"));
    CHECK_THAT(int_as_float, Contains("an integer in [1, 2048]"));

    const std::string boolean = parse_error("[colliders.sphere]\nenabled = 1\n");
    CHECK_THAT(boolean, Contains("test.toml:2:"));
    CHECK_THAT(boolean, Contains("colliders.sphere.enabled"));
    CHECK_THAT(boolean, Contains("true or false"));

    const std::string name = parse_error("name = 7\n");
    CHECK_THAT(name, Contains("test.toml:1:"));
    CHECK_THAT(name, Contains("name = 7"));
    CHECK_THAT(name, Contains("a string"));
}

TEST_CASE("scene file: an unknown field names it and lists the fields of its section") {
    const std::string msg = parse_error("name = \"x\"\n[cloth]\nrowz = 3\n");
    CHECK_THAT(msg, Contains("test.toml:3:"));
    CHECK_THAT(msg, Contains("unknown field 'cloth.rowz'"));
    CHECK_THAT(msg, Contains("[cloth]"));
    for (const char* field : {"rows", "cols", "size", "mass", "origin", "u_axis", "v_axis", "velocity"}) {
        CHECK_THAT(msg, Contains(field));
    }

    const std::string top = parse_error("nmae = \"x\"\n");
    CHECK_THAT(top, Contains("test.toml:1:"));
    CHECK_THAT(top, Contains("unknown field 'nmae'"));
    CHECK_THAT(top, Contains("name"));
}

TEST_CASE("scene file: an unknown section names it and lists the known top-level names") {
    const std::string msg = parse_error("name = \"x\"\n\n[clothes]\nrows = 3\n");
    CHECK_THAT(msg, Contains("test.toml:3:"));
    CHECK_THAT(msg, Contains("unknown field 'clothes'"));
    for (const char* section : {"name", "description", "cloth", "springs", "forces", "pins", "colliders", "integration"}) {
        CHECK_THAT(msg, Contains(section));
    }

    const std::string nested = parse_error("[colliders.cone]\nenabled = true\n");
    CHECK_THAT(nested, Contains("test.toml:1:"));
    CHECK_THAT(nested, Contains("unknown field 'colliders.cone'"));
    CHECK_THAT(nested, Contains("sphere"));
    CHECK_THAT(nested, Contains("cube"));
    CHECK_THAT(nested, Contains("cylinder"));
    CHECK_THAT(nested, Contains("ground"));
}

TEST_CASE("scene file: a section given as a value is rejected and its fields are listed") {
    const std::string msg = parse_error("name = \"x\"\ncloth = 5\n");
    CHECK_THAT(msg, Contains("test.toml:2:"));
    CHECK_THAT(msg, Contains("cloth is a section, not a value"));
    CHECK_THAT(msg, Contains("rows"));
    CHECK_THAT(msg, Contains("cols"));

    const std::string nested = parse_error("[colliders]\nsphere = true\n");
    CHECK_THAT(nested, Contains("test.toml:2:"));
    CHECK_THAT(nested, Contains("colliders.sphere is a section, not a value"));
    CHECK_THAT(nested, Contains("radius"));
}

TEST_CASE("scene file: a vector of the wrong length is rejected") {
    const std::string msg = parse_error("[forces]\ngravity = [0, -9.81]\n");
    CHECK_THAT(msg, Contains("test.toml:2:"));
    CHECK_THAT(msg, Contains("forces.gravity"));
    CHECK_THAT(msg, Contains("[x, y, z]"));
    CHECK_THAT(msg, Contains(allowed("forces.gravity")));

    const std::string longer = parse_error("[cloth]\nsize = [1, 2, 3]\n");
    CHECK_THAT(longer, Contains("test.toml:2:"));
    CHECK_THAT(longer, Contains("cloth.size"));
    CHECK_THAT(longer, Contains(allowed("cloth.size")));

    const std::string not_numbers = parse_error("[cloth]\norigin = [0, \"up\", 0]\n");
    CHECK_THAT(not_numbers, Contains("test.toml:2:"));
    CHECK_THAT(not_numbers, Contains("cloth.origin"));
}

TEST_CASE("scene file: a bad pin preset name lists the presets") {
    const std::string msg = parse_error("name = \"x\"\npins = \"bottom-row\"\n");
    CHECK_THAT(msg, Contains("test.toml:2:"));
    CHECK_THAT(msg, Contains("pins"));
    CHECK_THAT(msg, Contains("bottom-row"));
    for (std::string_view preset : clothsim::pin_preset_names()) CHECK_THAT(msg, Contains(std::string(preset)));

    const std::string table = parse_error("pins = { preset = \"sideways\" }\n");
    CHECK_THAT(table, Contains("test.toml:1:"));
    CHECK_THAT(table, Contains("top-corners"));

    const std::string bad_pair = parse_error("pins = [[0, 0], [1]]\n");
    CHECK_THAT(bad_pair, Contains("test.toml:1:"));
    CHECK_THAT(bad_pair, Contains("[row, col]"));

    const std::string wind = parse_error("[forces]\nwind_model = \"hurricane\"\n");
    CHECK_THAT(wind, Contains("test.toml:2:"));
    CHECK_THAT(wind, Contains("forces.wind_model"));
    CHECK_THAT(wind, Contains("one of triangles, uniform"));
}

TEST_CASE("scene file: a pin outside the grid names the pin, the grid and the allowed rows and columns") {
    const std::string msg = parse_error("pins = [[0, 0], [4, 1]]\n[cloth]\nrows = 4\ncols = 3\n");
    CHECK_THAT(msg, Contains("test.toml:1:"));  // cross-field errors point at the field they blame
    CHECK_THAT(msg, Contains("pins"));
    CHECK_THAT(msg, Contains("[4, 1]"));
    CHECK_THAT(msg, Contains("4 x 3 grid"));
    CHECK_THAT(msg, Contains("row in [0, 3], col in [0, 2]"));

    const std::string negative = parse_error("pins = { preset = \"top-row\", particles = [[0, -1]] }\n");
    CHECK_THAT(negative, Contains("test.toml"));
    CHECK_THAT(negative, Contains("[0, -1]"));
}

TEST_CASE("scene file: parallel u_axis and v_axis are rejected") {
    const std::string msg = parse_error("[cloth]\nu_axis = [1, 0, 0]\nv_axis = [-2, 0, 0]\n");
    CHECK_THAT(msg, Contains("test.toml:2:"));
    CHECK_THAT(msg, Contains("cloth.u_axis"));
    CHECK_THAT(msg, Contains("cloth.v_axis"));
    CHECK_THAT(msg, Contains("parallel"));
    CHECK_THAT(msg, Contains("non-parallel"));

    const std::string zero = parse_error("[cloth]\nu_axis = [0, 0, 0]\n");
    CHECK_THAT(zero, Contains("test.toml"));
    CHECK_THAT(zero, Contains("cloth.u_axis"));
    CHECK_THAT(zero, Contains("non-zero"));
}

TEST_CASE("scene file: a grid with too many particles is rejected") {
    const std::string msg = parse_error("[cloth]\nrows = 2048\ncols = 2048\n");
    CHECK_THAT(msg, Contains("test.toml:2:"));
    CHECK_THAT(msg, Contains("cloth.rows x cloth.cols"));
    CHECK_THAT(msg, Contains("4194304"));
    CHECK_THAT(msg, Contains(std::to_string(clothsim::kMaxParticles)));
}

TEST_CASE("scene file: bad files on disk are reported with their path and line") {
    SECTION("syntax error") {
        const auto path = kData / "scene_bad_syntax.toml";
        const std::string msg = load_error(path);
        CHECK_THAT(msg, Contains(path.string() + ":5:"));
        CHECK_THAT(msg, Contains("TOML syntax error"));
    }
    SECTION("out of range") {
        const auto path = kData / "scene_bad_range.toml";
        const std::string msg = load_error(path);
        CHECK_THAT(msg, Contains(path.string() + ":7:"));
        CHECK_THAT(msg, Contains("cloth.rows"));
        CHECK_THAT(msg, Contains("-3"));
        CHECK_THAT(msg, Contains("[1, 2048]"));
    }
    SECTION("unknown field") {
        const auto path = kData / "scene_unknown_field.toml";
        const std::string msg = load_error(path);
        CHECK_THAT(msg, Contains(path.string() + ":10:"));
        CHECK_THAT(msg, Contains("unknown field 'springs.stiffness'"));
        CHECK_THAT(msg, Contains("structural"));
    }
    SECTION("load_scene takes a path too") {
        const auto path = kData / "scene_bad_range.toml";
        std::string msg;
        try {
            clothsim::load_scene(path.string());
        } catch (const SceneError& e) {
            msg = e.what();
        }
        CHECK_THAT(msg, Contains(path.string() + ":7:"));
    }
}

TEST_CASE("scene file: a missing or unreadable file cannot be read") {
    const auto missing = kData / "no_such_scene.toml";
    const std::string msg = load_error(missing);
    CHECK_THAT(msg, Contains("cannot read scene file"));
    CHECK_THAT(msg, Contains(missing.string()));

    std::string via_load_scene;
    try {
        clothsim::load_scene(missing.string());
    } catch (const SceneError& e) {
        via_load_scene = e.what();
    }
    CHECK_THAT(via_load_scene, Contains("cannot read scene file"));
}

TEST_CASE("scene file: a directory is not a scene file") {
    // A directory opens as a stream on Linux but cannot be read; it must not load as an empty scene.
    const std::string msg = load_error(kData);
    CHECK_THAT(msg, Contains("cannot read scene file"));
    CHECK_THAT(msg, Contains(kData.string()));
}

TEST_CASE("scene file: a valid file from disk loads") {
    const clothsim::Scene s = clothsim::load_scene_file(kData / "scene_small.toml");
    CHECK(s.name == "small");
    CHECK(s.cloth.rows == 3);
    CHECK(s.cloth.cols == 2);
    CHECK(s.pins.preset == clothsim::PinPreset::TopRow);
    CHECK(s.pins.particles == std::vector<clothsim::Pin>{{2, 1}});
    CHECK(s.cloth.size == glm::vec2(0.5f, 0.5f));
    CHECK(clothsim::test::collider(s.settings.colliders, "sphere").enabled);
    CHECK(clothsim::test::sphere(s.settings.colliders).radius == 0.25f);
    CHECK(s.settings.forces.wind_model == clothsim::WindModel::Uniform);
    const clothsim::MassSpring sim = clothsim::build_simulation(s);
    CHECK(sim.particle_count() == 6);
}

// ---------------------------------------------------------------------------------------------------------
// --set overrides
// ---------------------------------------------------------------------------------------------------------

TEST_CASE("scene override: a rejected override leaves the scene exactly as it was") {
    clothsim::Scene scene = clothsim::load_scene("flag");
    clothsim::apply_override(scene, "cloth.rows=10");
    const std::string before = clothsim::to_toml(scene);
    for (const char* bad : {"cloth.rows=-3", "cloth.rows=abc", "cloth.rowz=3", "cloth.rows", "=3",
                            "forces.gravity=[0,-1]", "forces.gravity=[0,1e9,0]", "pins=sideways", "pins=[[10,0]]",
                            "cloth.v_axis=[1,0,0]", "cloth.u_axis=[0,0,0]", "cloth.cols=0",
                            "colliders.sphere.enabled=maybe", "integration.dt=0", "forces.wind_model=hurricane",
                            "cloth.size=[1,2,3]", "name=3"}) {
        INFO("--set " << bad);
        CHECK_THROWS_AS(clothsim::apply_override(scene, bad), SceneError);
        CHECK(clothsim::to_toml(scene) == before);
    }
    // Shrinking the grid under an explicit pin is a cross-field error and is not applied either.
    clothsim::apply_override(scene, "pins=[[9,3]]");
    const std::string with_pin = clothsim::to_toml(scene);
    const std::string msg = override_error(scene, "cloth.rows=5");
    CHECK_THAT(msg, Contains("--set cloth.rows=5"));
    CHECK_THAT(msg, Contains("[9, 3]"));
    CHECK_THAT(msg, Contains("5 x 36 grid"));
    CHECK(clothsim::to_toml(scene) == with_pin);
    CHECK(scene.cloth.rows == 10);
}

TEST_CASE("scene override: ints, floats, vectors, booleans, strings and bare words") {
    clothsim::Scene s = clothsim::per_spring_scene("hanging");  // springs.structural may be set below

    clothsim::apply_override(s, "cloth.rows=8");
    CHECK(s.cloth.rows == 8);
    clothsim::apply_override(s, "cloth.cols=6");
    CHECK(s.cloth.cols == 6);

    clothsim::apply_override(s, "springs.damping=0.75");
    CHECK(s.settings.springs.damping == 0.75f);
    clothsim::apply_override(s, "springs.structural=500");  // an integer for a float field
    CHECK(s.settings.springs.structural.x == 500.0f);
    clothsim::apply_override(s, "integration.dt=1e-3");
    CHECK(s.settings.integration.dt == 1e-3f);

    clothsim::apply_override(s, "forces.gravity=[0,-1,0]");
    CHECK(s.settings.forces.gravity == glm::vec3(0.0f, -1.0f, 0.0f));
    clothsim::apply_override(s, "forces.wind=[1.5, 0, -2]");
    CHECK(s.settings.forces.wind == glm::vec3(1.5f, 0.0f, -2.0f));

    clothsim::apply_override(s, "colliders.sphere.enabled=true");
    CHECK(clothsim::test::collider(s.settings.colliders, "sphere").enabled);
    clothsim::apply_override(s, "colliders.ground.enabled=false");
    CHECK_FALSE(clothsim::test::collider(s.settings.colliders, "ground").enabled);

    clothsim::apply_override(s, "pins=top-row");
    CHECK(s.pins.preset == clothsim::PinPreset::TopRow);
    CHECK(s.pins.particles.empty());
    clothsim::apply_override(s, "pins=\"four-corners\"");
    CHECK(s.pins.preset == clothsim::PinPreset::FourCorners);
    clothsim::apply_override(s, "pins=[[0,0],[7,5]]");
    CHECK(s.pins.preset == clothsim::PinPreset::None);
    CHECK(s.pins.particles == std::vector<clothsim::Pin>{{0, 0}, {7, 5}});
    clothsim::apply_override(s, "pins={ preset = \"left-edge\", particles = [[3, 3]] }");
    CHECK(s.pins.preset == clothsim::PinPreset::LeftEdge);
    CHECK(s.pins.particles == std::vector<clothsim::Pin>{{3, 3}});

    clothsim::apply_override(s, "forces.wind_model=uniform");
    CHECK(s.settings.forces.wind_model == clothsim::WindModel::Uniform);
    clothsim::apply_override(s, "forces.wind_model=triangles");
    CHECK(s.settings.forces.wind_model == clothsim::WindModel::Triangles);

    clothsim::apply_override(s, "cloth.size=2");  // one number: a square
    CHECK(s.cloth.size == glm::vec2(2.0f, 2.0f));
    clothsim::apply_override(s, "cloth.size=0.5");
    CHECK(s.cloth.size == glm::vec2(0.5f, 0.5f));
    clothsim::apply_override(s, "cloth.size=[1.5, 0.25]");
    CHECK(s.cloth.size == glm::vec2(1.5f, 0.25f));

    clothsim::apply_override(s, "name=\"my scene\"");
    CHECK(s.name == "my scene");
    clothsim::apply_override(s, "description=bare-word");
    CHECK(s.description == "bare-word");

    const clothsim::MassSpring sim = clothsim::build_simulation(s);
    CHECK(sim.particle_count() == 48);
}

TEST_CASE("scene override: unknown keys, missing '=', wrong types and out-of-range values are rejected") {
    clothsim::Scene s;

    const std::string unknown = override_error(s, "cloth.rowz=3");
    CHECK_THAT(unknown, Contains("--set cloth.rowz=3"));
    CHECK_THAT(unknown, Contains("unknown field 'cloth.rowz'"));
    for (const clothsim::FieldInfo& f : clothsim::scene_fields()) CHECK_THAT(unknown, Contains(std::string(f.name)));

    const std::string no_eq = override_error(s, "cloth.rows");
    CHECK_THAT(no_eq, Contains("--set cloth.rows"));
    CHECK_THAT(no_eq, Contains("expected key=value"));
    const std::string no_key = override_error(s, "=3");
    CHECK_THAT(no_key, Contains("--set =3"));
    CHECK_THAT(no_key, Contains("expected key=value"));

    const std::string type = override_error(s, "cloth.rows=abc");
    CHECK_THAT(type, Contains("--set cloth.rows=abc"));
    CHECK_THAT(type, Contains("cloth.rows"));
    CHECK_THAT(type, Contains("an integer in [1, 2048]"));
    const std::string fractional = override_error(s, "cloth.rows=2.5");
    CHECK_THAT(fractional, Contains("--set cloth.rows=2.5"));
    CHECK_THAT(fractional, Contains("[1, 2048]"));
    const std::string boolean = override_error(s, "colliders.cube.enabled=yes");
    CHECK_THAT(boolean, Contains("--set colliders.cube.enabled=yes"));
    CHECK_THAT(boolean, Contains("true or false"));
    const std::string vector = override_error(s, "forces.gravity=9.81");
    CHECK_THAT(vector, Contains("--set forces.gravity=9.81"));
    CHECK_THAT(vector, Contains(allowed("forces.gravity")));

    const std::string range = override_error(s, "cloth.rows=-3");
    CHECK_THAT(range, Contains("--set cloth.rows=-3"));
    CHECK_THAT(range, Contains("cloth.rows"));
    CHECK_THAT(range, Contains("-3"));
    CHECK_THAT(range, Contains("[1, 2048]"));
    const std::string float_range = override_error(s, "forces.gust_strength=1.5");
    CHECK_THAT(float_range, Contains("--set forces.gust_strength=1.5"));
    CHECK_THAT(float_range, Contains("forces.gust_strength"));
    CHECK_THAT(float_range, Contains(allowed("forces.gust_strength")));
    const std::string nan = override_error(s, "springs.damping=nan");
    CHECK_THAT(nan, Contains("springs.damping"));
    CHECK_THAT(nan, Contains(allowed("springs.damping")));
    const std::string inf = override_error(s, "springs.shear=inf");
    CHECK_THAT(inf, Contains("springs.shear"));

    const std::string parallel = override_error(s, "cloth.u_axis=[0,2,0]");
    CHECK_THAT(parallel, Contains("--set cloth.u_axis=[0,2,0]"));
    CHECK_THAT(parallel, Contains("parallel"));

    const std::string preset = override_error(s, "pins=bottom");
    CHECK_THAT(preset, Contains("--set pins=bottom"));
    CHECK_THAT(preset, Contains("one of none, top-corners, top-row, four-corners, left-edge"));

    CHECK(clothsim::to_toml(s) == clothsim::to_toml(clothsim::Scene{}));
}

// Both ends of every numeric field's documented range are allowed (the ranges are inclusive), through
// --set and through a scene file (cloth.mass = 1e-6 is stored as the float 9.99999997e-7, below 1e-6).
TEST_CASE("scene fields accept both ends of their documented range") {
    for (const clothsim::FieldInfo& field : clothsim::scene_fields()) {
        clothsim::Scene scratch;
        const clothsim::FieldRef ref = field.ref(scratch);
        const bool is_int = std::holds_alternative<int*>(ref);
        const bool is_float = std::holds_alternative<float*>(ref);
        const bool is_vec2 = std::holds_alternative<glm::vec2*>(ref);
        const bool is_vec3 = std::holds_alternative<glm::vec3*>(ref);
        if (!is_int && !is_float && !is_vec2 && !is_vec3) continue;
        for (double bound : {field.min, field.max}) {
            std::string text = is_int ? std::to_string(static_cast<long long>(bound)) : shortest(bound);
            if (is_vec2) text = "[" + text + ", " + text + "]";
            if (is_vec3) text = "[" + text + ", " + text + ", " + text + "]";
            // A vector axis at its bound must not end up parallel to the other axis.
            clothsim::Scene scene;
            if (field.name == "cloth.u_axis") scene.cloth.v_axis = {0.0f, -1.0f, 1.0f};
            const std::string assignment = std::string(field.name) + "=" + text;
            INFO("--set " << assignment);
            CHECK_NOTHROW(clothsim::apply_override(scene, assignment));

            // The same value from a scene file, as a dotted key.
            std::string file = std::string(field.name) + " = " + text + "\n";
            if (field.name == "cloth.u_axis") file += "cloth.v_axis = [0.0, -1.0, 1.0]\n";
            INFO("scene file:\n" << file);
            CHECK_NOTHROW(clothsim::parse_scene(file, "bounds.toml"));
        }
    }
}

// ---------------------------------------------------------------------------------------------------------
// to_toml
// ---------------------------------------------------------------------------------------------------------

TEST_CASE("scene to_toml: every bundled scene round-trips through to_toml and parse_scene") {
    for (const std::string& name : clothsim::bundled_scene_names()) {
        INFO("scene " << name);
        const clothsim::Scene s = clothsim::load_scene(name);
        const std::string text = clothsim::to_toml(s);
        const clothsim::Scene back = clothsim::parse_scene(text, name + ".roundtrip.toml");
        CHECK(clothsim::to_toml(back) == text);
        CHECK(back.name == s.name);
        CHECK(back.description == s.description);
        CHECK(back.pins == s.pins);
        CHECK(back.cloth.rows == s.cloth.rows);
        CHECK(back.cloth.cols == s.cloth.cols);
        CHECK(back.cloth.size == s.cloth.size);
        CHECK(back.cloth.origin == s.cloth.origin);
        CHECK(back.cloth.v_axis == s.cloth.v_axis);
        CHECK(back.settings.integration.dt == s.settings.integration.dt);
        CHECK(back.settings.forces.gravity == s.settings.forces.gravity);
        CHECK(back.settings.springs.damping == s.settings.springs.damping);
        // Every field, through its TOML text.
        for (const clothsim::FieldInfo& f : clothsim::scene_fields()) {
            CHECK(clothsim::format_value(back, f) == clothsim::format_value(s, f));
        }
    }
}

TEST_CASE("scene to_toml: a scene with explicit pin particles round-trips") {
    clothsim::Scene s;
    s.name = "pinned";
    s.cloth.rows = 6;
    s.cloth.cols = 5;
    s.pins.preset = clothsim::PinPreset::TopCorners;
    s.pins.particles = {{5, 4}, {2, 3}, {0, 0}};
    s.settings.springs.damping = 0.2f;
    s.settings.integration.dt = 1.0f / 60.0f;
    const std::string text = clothsim::to_toml(s);
    CHECK_THAT(text, Contains("particles = [[5, 4], [2, 3], [0, 0]]"));
    CHECK_THAT(text, Contains("damping = 0.2\n"));
    const clothsim::Scene back = clothsim::parse_scene(text, "pinned.toml");
    CHECK(back.pins == s.pins);
    CHECK(back.settings.integration.dt == s.settings.integration.dt);
    CHECK(clothsim::to_toml(back) == text);

    // Explicit particles only (preset none) round-trip as well.
    s.pins = {clothsim::PinPreset::None, {{1, 1}}};
    const clothsim::Scene only = clothsim::parse_scene(clothsim::to_toml(s), "only.toml");
    CHECK(only.pins == s.pins);
    CHECK(clothsim::to_toml(only) == clothsim::to_toml(s));
}

TEST_CASE("scene to_toml: names and descriptions with quotes, backslashes and newlines round-trip") {
    clothsim::Scene s;
    s.name = "say \"hi\" \\ there";
    s.description = "line one\nline two\twith a tab";
    const std::string text = clothsim::to_toml(s);
    const clothsim::Scene back = clothsim::parse_scene(text, "quoted.toml");
    CHECK(back.name == s.name);
    CHECK(back.description == s.description);
    CHECK(clothsim::to_toml(back) == text);
}

TEST_CASE("scene to_toml: a description with control characters round-trips") {
    // A file may give any character through TOML escapes; to_toml must write it back readable.
    const clothsim::Scene s = clothsim::parse_scene("description = \"a\\rb\\u0001c\\u007fd\\be\"\n", "ctl.toml");
    REQUIRE(s.description == std::string("a\rb\x01" "c\x7f" "d\be"));
    std::string message = "(no SceneError thrown)";
    clothsim::Scene back;
    try {
        back = clothsim::parse_scene(clothsim::to_toml(s), "ctl.roundtrip.toml");
    } catch (const SceneError& e) {
        message = e.what();
    }
    CHECK(message == "(no SceneError thrown)");
    CHECK(back.description == s.description);
}

TEST_CASE("scene to_toml: field values at the ends of their ranges round-trip") {
    clothsim::Scene s;
    clothsim::apply_override(s, "integration.dt=1e-7");
    clothsim::apply_override(s, "springs.structural=1e9");
    clothsim::apply_override(s, "colliders.ground.height=-10000");
    clothsim::apply_override(s, "forces.gravity=[0, -100000, 0.125]");
    clothsim::apply_override(s, "cloth.velocity=[-0.0, 1e-30, 3.4028234e+2]");
    const std::string text = clothsim::to_toml(s);
    const clothsim::Scene back = clothsim::parse_scene(text, "bounds.toml");
    CHECK(clothsim::to_toml(back) == text);
    CHECK(back.settings.integration.dt == s.settings.integration.dt);
    CHECK(back.settings.springs.structural == s.settings.springs.structural);
    CHECK(back.cloth.velocity == s.cloth.velocity);
}

// ---------------------------------------------------------------------------------------------------------
// Pins
// ---------------------------------------------------------------------------------------------------------

TEST_CASE("scene pins: pinned_particles of every preset on a 4 x 5 grid") {
    clothsim::ClothSettings cloth;
    cloth.rows = 4;
    cloth.cols = 5;
    using V = std::vector<std::size_t>;
    auto pins = [&](clothsim::PinPreset preset) { return clothsim::pinned_particles(cloth, {preset, {}}); };
    CHECK(pins(clothsim::PinPreset::None) == V{});
    CHECK(pins(clothsim::PinPreset::TopCorners) == V{0, 4});
    CHECK(pins(clothsim::PinPreset::TopRow) == V{0, 1, 2, 3, 4});
    CHECK(pins(clothsim::PinPreset::FourCorners) == V{0, 4, 15, 19});
    CHECK(pins(clothsim::PinPreset::LeftEdge) == V{0, 5, 10, 15});
    CHECK(pins(clothsim::PinPreset::Center) == V{7});  // row 1, column 2: (rows - 1) / 2, (cols - 1) / 2
    REQUIRE(clothsim::pin_preset_names().size() == 6);
    // With a radius, the centre's clip stays centred as the grid is refined (the Cusick clamp): its particles'
    // mean rest position is the cloth's centre, and it holds the same area of cloth, at 41, 61 and 81 a side.
    for (int n : {41, 61, 81}) {
        clothsim::ClothSettings disc;
        disc.rows = disc.cols = n;
        disc.size = {0.3f, 0.3f};
        const V held = clothsim::pinned_particles(disc, {clothsim::PinPreset::Center, {}, 0.09f});
        double sum_r = 0.0, sum_c = 0.0;
        for (std::size_t i : held) sum_r += double(i / n), sum_c += double(i % n);
        INFO(n << " a side: " << held.size() << " particles held");
        CHECK(sum_r / double(held.size()) == Approx((n - 1) / 2.0));
        CHECK(sum_c / double(held.size()) == Approx((n - 1) / 2.0));
        const double h = 0.3 / (n - 1), area = double(held.size()) * h * h;
        CHECK(area == Approx(3.14159265 * 0.09 * 0.09).epsilon(0.05));
    }

    // Explicit particles are added to the preset, row-major, sorted, without duplicates.
    CHECK(clothsim::pinned_particles(cloth, {clothsim::PinPreset::TopCorners, {{3, 2}, {0, 4}, {1, 0}}}) ==
          V{0, 4, 5, 17});
    CHECK(clothsim::pinned_particles(cloth, {clothsim::PinPreset::None, {{3, 4}}}) == V{19});

    // A pin outside the grid is an error naming it.
    CHECK_THROWS_WITH(clothsim::pinned_particles(cloth, {clothsim::PinPreset::None, {{4, 0}}}),
                      Contains("[4, 0]") && Contains("4 x 5 grid"));
    CHECK_THROWS_AS(clothsim::pinned_particles(cloth, {clothsim::PinPreset::None, {{0, -1}}}), SceneError);

    // One column: the two top corners are the same particle.
    cloth.cols = 1;
    CHECK(pins(clothsim::PinPreset::TopCorners) == V{0});
    CHECK(pins(clothsim::PinPreset::FourCorners) == V{0, 3});
}

TEST_CASE("scene pins: clips are read from a pins list, a pins table and --set") {
    using Clips = std::vector<clothsim::Pin>;
    const clothsim::Scene preset =
        clothsim::parse_scene("pins = { preset = \"top-corners\", radius = 0.02 }\n", "t.toml");
    CHECK(preset.pins.preset == clothsim::PinPreset::TopCorners);
    CHECK(preset.pins.preset_radius == 0.02f);
    CHECK(preset.pins.particles.empty());

    const clothsim::Scene list = clothsim::parse_scene(
        "pins = [[0, 0], { particle = [3, 1], radius = 0.05 }, { particle = [2, 2] }]\n", "t.toml");
    CHECK(list.pins.preset == clothsim::PinPreset::None);
    CHECK(list.pins.preset_radius == 0.0f);
    CHECK(list.pins.particles == Clips{{0, 0, 0.0f}, {3, 1, 0.05f}, {2, 2, 0.0f}});

    const clothsim::Scene table = clothsim::parse_scene(
        "pins = { preset = \"left-edge\", radius = 0, particles = [{ radius = 1, particle = [1, 2] }] }\n", "t.toml");
    CHECK(table.pins.preset == clothsim::PinPreset::LeftEdge);
    CHECK(table.pins.preset_radius == 0.0f);
    CHECK(table.pins.particles == Clips{{1, 2, 1.0f}});

    clothsim::Scene s;
    clothsim::apply_override(
        s, "pins={ preset = \"top-row\", radius = 0.01, particles = [{ particle = [7, 5], radius = 0.3 }] }");
    CHECK(s.pins.preset == clothsim::PinPreset::TopRow);
    CHECK(s.pins.preset_radius == 0.01f);
    CHECK(s.pins.particles == Clips{{7, 5, 0.3f}});
    // A preset name alone drops the clip radius with the rest of the old pins.
    clothsim::apply_override(s, "pins=top-corners");
    CHECK(s.pins == clothsim::PinSpec{});

    // How clips hold: rigid unless the table says soft.
    CHECK(preset.pins.clip == clothsim::ClipKind::Rigid);
    const clothsim::Scene soft =
        clothsim::parse_scene("pins = { preset = \"top-corners\", radius = 0.15, clip = \"soft\" }\n", "t.toml");
    CHECK(soft.pins.clip == clothsim::ClipKind::Soft);
    CHECK(soft.pins.preset_radius == 0.15f);
    clothsim::apply_override(s, "pins={ preset = \"top-row\", radius = 0.01, clip = \"soft\" }");
    CHECK(s.pins.clip == clothsim::ClipKind::Soft);
    clothsim::apply_override(s, "pins={ preset = \"top-row\", radius = 0.01, clip = \"rigid\" }");
    CHECK(s.pins.clip == clothsim::ClipKind::Rigid);
}

TEST_CASE("scene pins: clips round-trip through to_toml, radius 0 as a plain [row, col]") {
    clothsim::Scene s;
    s.cloth.rows = 6;
    s.cloth.cols = 5;
    s.pins = {clothsim::PinPreset::TopCorners, {{5, 4, 0.0f}, {2, 3, 0.05f}}, 0.02f};
    const std::string text = clothsim::to_toml(s);
    CHECK_THAT(text, Contains("pins = { preset = \"top-corners\", radius = 0.02, particles = [[5, 4], "
                              "{ particle = [2, 3], radius = 0.05 }] }\n"));
    const clothsim::Scene back = clothsim::parse_scene(text, "clips.toml");
    CHECK(back.pins == s.pins);
    CHECK(clothsim::to_toml(back) == text);

    // The preset's radius alone; explicit clips alone; the largest radius; a radius that is no short decimal.
    for (const clothsim::PinSpec& pins :
         {clothsim::PinSpec{clothsim::PinPreset::FourCorners, {}, 0.125f},
          clothsim::PinSpec{clothsim::PinPreset::None, {{1, 1, 1.0f}, {0, 4, 1e-7f}}},
          clothsim::PinSpec{clothsim::PinPreset::LeftEdge, {{3, 0, 0.1f / 3.0f}}, 0.7f},
          clothsim::PinSpec{clothsim::PinPreset::TopCorners, {}, 0.15f, clothsim::ClipKind::Soft},
          clothsim::PinSpec{clothsim::PinPreset::None, {{2, 3, 0.05f}}, 0.0f, clothsim::ClipKind::Soft}}) {
        s.pins = pins;
        const std::string written = clothsim::to_toml(s);
        INFO(written);
        const clothsim::Scene again = clothsim::parse_scene(written, "again.toml");
        CHECK(again.pins == pins);
        CHECK(clothsim::to_toml(again) == written);
    }
    // Point pins keep the short forms they had before clips existed.
    s.pins = {clothsim::PinPreset::TopRow, {}};
    CHECK(clothsim::format_value(s, *clothsim::find_field("pins")) == "\"top-row\"");
    s.pins = {clothsim::PinPreset::None, {{1, 1}}};
    CHECK(clothsim::format_value(s, *clothsim::find_field("pins")) == "{ preset = \"none\", particles = [[1, 1]] }");
    s.pins = {clothsim::PinPreset::TopCorners, {}, 0.15f, clothsim::ClipKind::Soft};
    CHECK(clothsim::format_value(s, *clothsim::find_field("pins")) ==
          "{ preset = \"top-corners\", radius = 0.15, clip = \"soft\" }");
}

TEST_CASE("scene pins: a bad clip is rejected with its line, the part at fault and what is allowed") {
    // A negative radius, in the table and in a list entry on its own line.
    const std::string negative = parse_error("name = \"x\"\npins = { preset = \"top-corners\", radius = -0.01 }\n");
    CHECK_THAT(negative, Contains("test.toml:2:"));
    CHECK_THAT(negative, Contains("pins.radius = -0.01 is out of range; allowed: a number in [0.0, 1.0] m"));
    const std::string entry = parse_error("pins = [\n  [0, 0],\n  { particle = [0, 3], radius = -1 },\n]\n");
    CHECK_THAT(entry, Contains("test.toml:3:"));
    CHECK_THAT(entry, Contains("pins[1].radius = -1 is out of range"));
    CHECK_THAT(parse_error("pins = { preset = \"none\", particles = [{ particle = [0, 0], radius = 2 }] }\n"),
               Contains("pins.particles[0].radius = 2 is out of range; allowed: a number in [0.0, 1.0] m"));
    CHECK_THAT(parse_error("pins = { preset = \"top-row\", radius = nan }\n"),
               Contains("pins.radius = nan is out of range"));

    // Unknown keys, in a clip and in the pins table, with the keys that are known.
    CHECK_THAT(parse_error("pins = [{ particle = [0, 0], radios = 0.1 }]\n"),
               Contains("pins[0] has an unknown key 'radios'; allowed keys: particle, vertex, radius"));
    CHECK_THAT(parse_error("pins = { preset = \"none\", grip = 0.1 }\n"),
               Contains("pins has an unknown key 'grip'; allowed keys: preset, radius, particles, clip"));
    // A clip kind that is not one.
    CHECK_THAT(parse_error("pins = { preset = \"top-corners\", radius = 0.05, clip = \"padded\" }\n"),
               Contains("pins.clip = 'padded' is not a clip kind; allowed: rigid, soft"));
    CHECK_THAT(parse_error("pins = { preset = \"none\", clip = 0.1 }\n"),
               Contains("pins.clip = 0.1 is not a clip kind; allowed: rigid, soft"));
    // Soft with no clip to hold softly (point pins stay rigid): refused, saying what soft needs.
    for (const char* pins : {"pins = { preset = \"top-corners\", clip = \"soft\" }\n",
                             "pins = { particles = [[0, 0], [0, 3]], clip = \"soft\" }\n",
                             "pins = { radius = 0.15, clip = \"soft\" }\n"}) {  // a radius, but no preset pin
        CHECK_THAT(parse_error(pins), Contains("pins: clip = \"soft\" has no clip to hold softly: no pin has a radius; "
                                               "allowed with clip = \"soft\": pins.radius > 0"));
    }

    // Wrong types.
    CHECK_THAT(parse_error("pins = [{ particle = [0, 0], radius = \"wide\" }]\n"),
               Contains("pins[0].radius = 'wide' is not a number; allowed: a number in [0.0, 1.0] m"));
    CHECK_THAT(parse_error("pins = [{ particle = 3, radius = 0.1 }]\n"),
               Contains("pins[0].particle = 3 is not a particle; allowed: [row, col], two integers"));
    CHECK_THAT(parse_error("pins = [{ radius = 0.1 }]\n"),
               Contains("pins[0] = { radius = 0.1 } names no particle; allowed: "
                        "{ particle = [row, col], radius = R }"));
    CHECK_THAT(parse_error("pins = [[0, 0], true]\n"),
               Contains("pins[1] = true is not a pin; allowed: [row, col] or { particle = [row, col], radius = R }"));
    CHECK_THAT(parse_error("pins = { particles = 5 }\n"), Contains("pins.particles = 5 is not a list"));

    // A clip centred outside the grid, as a point pin outside it.
    const std::string outside =
        parse_error("pins = [{ particle = [4, 0], radius = 0.5 }]\n[cloth]\nrows = 4\ncols = 3\n");
    CHECK_THAT(outside, Contains("test.toml:1:"));
    CHECK_THAT(outside, Contains("[4, 0]") && Contains("row in [0, 3], col in [0, 2]"));

    // --set names the flag; the scene is left as it was.
    clothsim::Scene scene;
    const clothsim::Scene before = scene;
    const std::string set = override_error(scene, "pins={ preset = \"top-row\", radius = -1 }");
    CHECK_THAT(set, Contains("--set pins=") && Contains("pins.radius = -1 is out of range"));
    CHECK(scene.pins == before.pins);

    // A scene made in code is checked too (validate, build_simulation).
    scene.pins.preset_radius = -0.5f;
    CHECK_THROWS_WITH(clothsim::validate(scene),
                      Contains("pins: radius = -0.5 is out of range; allowed: a number in [0.0, 1.0] m"));
    scene.pins = {clothsim::PinPreset::None, {{1, 1, 1.5f}}};
    CHECK_THROWS_WITH(clothsim::build_simulation(scene),
                      Contains("pins: the radius of the clip at [1, 1] = 1.5 is out of range"));
}

TEST_CASE("scene build: build_simulation pins the particles of the scene") {
    clothsim::Scene s;
    s.cloth.rows = 4;
    s.cloth.cols = 5;
    s.pins = {clothsim::PinPreset::FourCorners, {{2, 2}}};
    const clothsim::MassSpring sim = clothsim::build_simulation(s);
    REQUIRE(sim.particle_count() == 20);
    for (std::size_t i = 0; i < 20; ++i) {
        INFO("particle " << i);
        const bool expected = i == 0 || i == 4 || i == 15 || i == 19 || i == 12;
        CHECK(static_cast<bool>(sim.state().pinned[i]) == expected);
    }
    s.pins = {clothsim::PinPreset::None, {{4, 0}}};
    CHECK_THROWS_AS(clothsim::build_simulation(s), SceneError);
}

// ---------------------------------------------------------------------------------------------------------
// Found by fuzzing (tests/fuzz): each kept as a regression test here too
// ---------------------------------------------------------------------------------------------------------

TEST_CASE("scene file: a pin coordinate beyond int is rejected, not wrapped onto another particle") {
    const std::string error = parse_error("pins = [[4294967296, 0]]\n[cloth]\nrows = 4\ncols = 4\n");
    CHECK_THAT(error, Contains("pins"));
    CHECK_THAT(parse_error("pins = [[0, -4294967295]]\n"), Contains("pins"));
}

TEST_CASE("scene --set: a value spanning lines is rejected instead of half applied") {
    clothsim::Scene scene;
    const clothsim::Scene before = scene;
    CHECK_THAT(override_error(scene, "cloth.rows=8\ncloth.cols=9"), Contains("spans lines"));
    CHECK(scene.cloth.rows == before.cloth.rows);
    CHECK(scene.cloth.cols == before.cloth.cols);
}

TEST_CASE("scene --set: a bare value that is not UTF-8 is rejected, so every scene saves and loads back") {
    clothsim::Scene scene;
    CHECK_THAT(override_error(scene, "name=\xff\xfe\xc3\x28"), Contains("not valid UTF-8"));
    CHECK(scene.name == "untitled");
    clothsim::apply_override(scene, "name=caf\xc3\xa9");  // valid UTF-8 is kept
    CHECK(clothsim::parse_scene(clothsim::to_toml(scene), "round trip").name == "caf\xc3\xa9");
}

TEST_CASE("scene file: an error message that quotes inf, nan or INT64_MIN in an array is well defined") {
    CHECK_THAT(parse_error("[forces]\ngravity = [0.0, -inf, 0.0]\n"), Contains("-inf"));
    CHECK_THAT(parse_error("[forces]\nwind = [nan, 0.0, 0.0]\n"), Contains("nan"));
    CHECK_THAT(parse_error("[cloth]\nsize = [-9223372036854775808, 1]\n"), Contains("cloth.size"));
}

TEST_CASE("scene clamp_to_range: every field typed far out of range is clamped with a note, and the scene saves and reopens") {
    using namespace clothsim;
    for (double typed : {1e9, -1e9, std::nan(""), 1e-30, -1e-30}) {
        INFO("typed " << typed);
        // Per spring: every typed field is one the scene holds itself (a material derives cloth.mass and the
        // springs, and validate() checks the derived mass against cloth.mass's range).
        Scene scene = per_spring_scene("flag");
        int notes = 0;
        for (const FieldInfo& f : scene_fields()) {
            std::visit(Overloaded{
                           [&](int* v) { *v = std::isnan(typed) ? 0 : static_cast<int>(std::clamp(typed, -2e9, 2e9)); },
                           [&](float* v) { *v = static_cast<float>(typed); },
                           [&](glm::vec2* v) { *v = glm::vec2(static_cast<float>(typed)); },
                           [&](glm::vec3* v) { *v = glm::vec3(static_cast<float>(typed)); },
                           [&](auto*) {},
                       },
                       f.ref(scene));
            if (const auto note = clamp_to_range(scene, f)) {
                ++notes;
                CHECK_THAT(*note, Catch::Contains(std::string(f.name)) && Catch::Contains("allowed"));
            }
            CHECK_FALSE(clamp_to_range(scene, f).has_value());  // clamped values are allowed
        }
        if (!(std::abs(typed) < 1.0)) CHECK(notes > 10);  // huge or NaN: most fields refuse it
        // The axes must not be parallel or zero (a rule across fields): give them back their directions.
        scene.cloth.u_axis = {1.0f, 0.0f, 0.0f};
        scene.cloth.v_axis = {0.0f, -1.0f, 0.0f};
        scene.cloth.rows = std::min(scene.cloth.rows, 64);
        scene.cloth.cols = std::min(scene.cloth.cols, 64);
        scene.pins.particles.clear();
        REQUIRE_NOTHROW(validate(scene));
        const Scene reopened = parse_scene(to_toml(scene), "saved.toml");
        CHECK(reopened.settings == scene.settings);
    }
}

TEST_CASE("scene file: the cylinder collider loads, overrides, round-trips and rejects bad values") {
    using namespace clothsim;
    const std::vector<Collider>& defaults = Scene{}.settings.colliders.shapes;
    CHECK(std::none_of(defaults.begin(), defaults.end(), [](const Collider& x) {
        return std::holds_alternative<CylinderCollider>(x.shape) && x.enabled;
    }));  // off unless a scene asks for it
    const Scene s = parse_scene("[colliders.cylinder]\nenabled = true\ncenter = [0.1, 0.25, -0.2]\n"
                                "radius = 0.09\nheight = 0.5\nfriction = 0.45\n",
                                "test.toml");
    const Collider& collider = test::collider(s.settings.colliders, "cylinder");
    const CylinderCollider& c = test::cylinder(s.settings.colliders);
    CHECK(collider.enabled);
    CHECK(c.center == glm::vec3(0.1f, 0.25f, -0.2f));
    CHECK(c.radius == 0.09f);
    CHECK(c.height == 0.5f);
    CHECK(collider.friction == 0.45f);
    const std::string text = to_toml(s);
    CHECK_THAT(text, Contains("kind = \"cylinder\"") && Contains("radius = 0.09") && Contains("height = 0.5"));
    CHECK(parse_scene(text, "saved.toml").settings == s.settings);

    Scene o;
    apply_override(o, "colliders.cylinder.enabled=true");
    apply_override(o, "colliders.cylinder.center=[0, 0.3, 0]");
    apply_override(o, "colliders.cylinder.radius=0.09");
    apply_override(o, "colliders.cylinder.height=0.6");
    apply_override(o, "colliders.cylinder.friction=0");
    CHECK(test::collider(std::as_const(o.settings.colliders), "cylinder") ==
          Collider{CylinderCollider{{0.0f, 0.3f, 0.0f}, 0.09f, 0.6f}, 0.0f, true, {}});

    const std::string height = parse_error("[colliders.cylinder]\nheight = -0.1\n");
    CHECK_THAT(height, Contains("test.toml:2:") && Contains("colliders.cylinder.height") &&
                           Contains("a number in [0.0, 10000.0] m"));
    Scene unchanged = o;
    CHECK_THAT(override_error(unchanged, "colliders.cylinder.radius=-1"),
               Contains("colliders.cylinder.radius") && Contains(allowed_collider("cylinder", "radius")));
    CHECK_THAT(override_error(unchanged, "colliders.cylinder.friction=11"),
               Contains("colliders.cylinder.friction") && Contains(allowed_collider("cylinder", "friction")));
    CHECK(unchanged.settings == o.settings);
}

TEST_CASE("scene file: the contact model and its stiffness load, override, round-trip and reject bad values") {
    using namespace clothsim;
    const Scene s = parse_scene("[colliders]\ncontact = \"penalty\"\ncontact_stiffness = 2500.0\n", "test.toml");
    CHECK(s.settings.colliders.contact == ContactModel::Penalty);
    CHECK(s.settings.colliders.contact_stiffness == 2500.0f);
    CHECK(Scene{}.settings.colliders.contact == ContactModel::Projection);  // the default: today's contact
    const Scene reopened = parse_scene(to_toml(s), "saved.toml");
    CHECK(reopened.settings == s.settings);
    CHECK_THAT(to_toml(s), Contains("contact = \"penalty\"") && Contains("contact_stiffness = 2500.0"));

    Scene o;
    apply_override(o, "colliders.contact=penalty");
    apply_override(o, "colliders.contact_stiffness=4e4");
    CHECK(o.settings.colliders.contact == ContactModel::Penalty);
    CHECK(o.settings.colliders.contact_stiffness == 4e4f);

    const std::string model = parse_error("[colliders]\ncontact = \"springy\"\n");
    CHECK_THAT(model, Contains("test.toml:2:") && Contains("colliders.contact") && Contains("springy") &&
                          Contains("one of projection, penalty"));
    const std::string stiffness = parse_error("[colliders]\ncontact_stiffness = 0.0\n");
    CHECK_THAT(stiffness, Contains("test.toml:2:") && Contains("colliders.contact_stiffness") &&
                              Contains("a number in [1.0, 1e+09] N/m"));
    Scene unchanged = o;
    CHECK_THAT(override_error(unchanged, "colliders.contact_stiffness=-5"),
               Contains("colliders.contact_stiffness") && Contains(allowed("colliders.contact_stiffness")));
    CHECK(unchanged.settings == o.settings);
    // Penalty contact pushes inside the thickness shell: a thickness of 0 leaves it nothing to push in.
    const std::string no_shell = parse_error("[colliders]\nthickness = 0.0\ncontact = \"penalty\"\n");
    CHECK_THAT(no_shell, Contains("test.toml:2:") && Contains("colliders.thickness") && Contains("penalty"));
    CHECK_THAT(override_error(unchanged, "colliders.thickness=0"), Contains("colliders.thickness"));
    CHECK_NOTHROW(parse_scene("[colliders]\nthickness = 0.0\n", "test.toml"));  // projection allows it
}

TEST_CASE("scene copy_field: every field of every kind takes the other scene's value (the panel's reset)") {
    using namespace clothsim;
    // The sources: every bundled scene; the target: the built-in defaults. Every field that differs is copied
    // alone and must then read as in the source, with every other field of the target untouched.
    std::vector<std::string> kinds_copied;
    int copies = 0;
    for (const std::string& name : bundled_scene_names()) {
        const Scene source = load_scene(name);
        for (const FieldInfo& f : scene_fields()) {
            const Scene defaults{};
            if (format_value(defaults, f) == format_value(source, f)) continue;
            Scene target{};
            copy_field(f, source, target);
            INFO(name << ": " << f.name);
            CHECK(format_value(target, f) == format_value(source, f));
            for (const FieldInfo& other : scene_fields()) {
                if (other.name != f.name) CHECK(format_value(target, other) == format_value(defaults, other));
            }
            ++copies;
            kinds_copied.push_back(std::visit([](const auto* p) { return std::string(typeid(*p).name()); }, f.read(source)));
        }
    }
    std::sort(kinds_copied.begin(), kinds_copied.end());
    kinds_copied.erase(std::unique(kinds_copied.begin(), kinds_copied.end()), kinds_copied.end());
    CHECK(copies > 50);
    CHECK(kinds_copied.size() >= 7);  // int, float, bool, vec2, vec3, string, pins and enumerations among them
}

TEST_CASE("scene file: a collider's velocity and spin load, override, round-trip, a spin its shape cannot follow is refused") {
    using namespace clothsim;
    const Scene s = parse_scene("[[colliders.shapes]]\nkind = \"sphere\"\ncenter = [0, 0.3, -1]\nradius = 0.3\n"
                                "velocity = [0, 0, 0.5]\nspin = [-95.5, 0, 0]\n",
                                "test.toml");
    const Collider& ball = s.settings.colliders.shapes.at(0);
    CHECK(ball.motion.velocity == glm::vec3(0.0f, 0.0f, 0.5f));
    CHECK(ball.motion.spin == glm::vec3(-95.5f, 0.0f, 0.0f));
    const std::string text = to_toml(s);
    CHECK_THAT(text, Contains("velocity = [0.0, 0.0, 0.5]") && Contains("spin = [-95.5, 0.0, 0.0]"));
    CHECK(parse_scene(text, "saved.toml").settings == s.settings);
    // A still collider's entry carries no motion rows.
    const std::string still = to_toml(Scene{});
    CHECK_THAT(still.substr(still.find("[[colliders.shapes]]")), !Contains("velocity") && !Contains("spin"));

    Scene o;
    apply_override(o, "colliders.shapes.0.velocity=[1, 0, 0]");
    CHECK(o.settings.colliders.shapes.at(0).motion.velocity == glm::vec3(1.0f, 0.0f, 0.0f));

    CHECK_THAT(parse_error("[[colliders.shapes]]\nkind = \"sphere\"\nvelocity = [0, 0, 1000]\n"),
               Contains("test.toml:3:") && Contains("velocity") && Contains("[-100.0, 100.0] m/s"));
    CHECK_THAT(parse_error("[[colliders.shapes]]\nkind = \"box\"\nspin = [0, 30, 0]\n"),
               Contains("colliders.shapes[0] (box): spin = [0.0, 30.0, 0.0]") && Contains("axis-aligned"));
    CHECK_THAT(parse_error("[[colliders.shapes]]\nkind = \"cylinder\"\nspin = [10, 0, 0]\n"),
               Contains("cylinder stays vertical") && Contains("[0, w, 0]"));
    Scene unchanged = o;
    CHECK_THAT(override_error(unchanged, "colliders.shapes.0.spin=[5, 0, 0]"), Contains("horizontal"));
    CHECK(unchanged.settings == o.settings);
}
