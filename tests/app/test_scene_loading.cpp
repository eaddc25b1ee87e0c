// open_scene: what the panel's Open does. A rejected file changes nothing the user has.
#include "scene_loading.hpp"

#include "app/run_process.hpp"
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "clothsim/mesh_file.hpp"
#include "clothsim/mesh_shapes.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

using namespace clothsim;
using Catch::Matchers::Contains;

namespace {

const std::filesystem::path kData = CLOTHSIM_TEST_DATA;

// hanging in the per-spring form, whose springs.structural the user edits (a material scene derives it).
struct Session {
    Scene edited, loaded;
    MassSpring sim;
    Session() : edited(per_spring_scene("hanging")), loaded(edited), sim(build_simulation(edited)) {
        edited.settings.springs.structural = glm::vec2(123.0f);  // the user's edit, not yet saved
        sim.run_steps(3);
    }
};

void check_untouched(const Session& s, const std::vector<glm::vec3>& positions, double time) {
    CHECK(s.edited.settings.springs.structural.x == 123.0f);
    CHECK(s.loaded.settings.springs.structural.x == 400.0f);
    CHECK(s.edited.name == "hanging");
    CHECK(s.sim.positions() == positions);
    CHECK(s.sim.time() == time);
}

}  // namespace

TEST_CASE("open_scene: a file that does not parse keeps the edits and the running cloth, and says where") {
    Session s;
    const auto positions = s.sim.positions();
    const double time = s.sim.time();
    const auto error = open_scene((kData / "scene_bad_syntax.toml").string(), s.edited, s.loaded, s.sim);
    REQUIRE(error);
    CHECK_THAT(*error, Contains("scene_bad_syntax.toml:5:"));  // file:line:column
    check_untouched(s, positions, time);
}

TEST_CASE("open_scene: a value out of range, a missing file, pins outside the grid: nothing changes") {
    Session s;
    const auto positions = s.sim.positions();
    const double time = s.sim.time();
    auto error = open_scene((kData / "scene_bad_range.toml").string(), s.edited, s.loaded, s.sim);
    REQUIRE(error);
    check_untouched(s, positions, time);
    error = open_scene((kData / "no-such-file.toml").string(), s.edited, s.loaded, s.sim);
    REQUIRE(error);
    CHECK_THAT(*error, Contains("no-such-file.toml"));
    check_untouched(s, positions, time);
    // Parses and validates, but fails only when the cloth is built: still all or nothing.
    const std::filesystem::path pins = std::filesystem::temp_directory_path() / "clothsim-pins-outside.toml";
    {
        std::ofstream(pins) << "name = \"p\"\npins = [[40, 40]]\n[cloth]\nrows = 4\ncols = 4\n";
    }
    error = open_scene(pins.string(), s.edited, s.loaded, s.sim);
    std::filesystem::remove(pins);
    REQUIRE(error);
    CHECK_THAT(*error, Contains("outside"));
    check_untouched(s, positions, time);
}

TEST_CASE("open_scene: a good file replaces the edited scene, the reset target and the cloth together") {
    Session s;
    const auto error = open_scene((kData / "scene_small.toml").string(), s.edited, s.loaded, s.sim);
    REQUIRE_FALSE(error);
    CHECK(s.edited.name == "small");
    CHECK(s.loaded.name == "small");
    CHECK(s.sim.particle_count() == 6);
    CHECK(s.sim.time() == 0.0);
}

TEST_CASE("running_scene: a panel change reaches the next substep and is what Save writes") {
    // What the panel does with an edit: the simulation's one call, MassSpring::apply. Per spring: the edit below
    // is to springs.structural, which Save writes only for a scene in that form.
    Scene document = per_spring_scene("hanging");
    // One substep per step: a long substep makes the first fall (g h^2) large against float round-off.
    document.settings.integration.substeps = 1;
    MassSpring sim = build_simulation(document);
    MassSpring earth = sim;
    MassSpring weightless = sim;
    SimulationSettings edit = sim.settings();
    edit.forces.gravity = {0.0f, -1.62f, 0.0f};  // the Moon
    edit.springs.structural = glm::vec2(250.0f);
    sim.apply(edit);
    CHECK(sim.settings().forces.gravity.y == -1.62f);
    test::edit_settings(weightless, [](SimulationSettings& s) {
        s.forces.gravity = glm::vec3(0.0f);
        s.springs.structural = glm::vec2(250.0f);
    });
    test::edit_settings(earth, [](SimulationSettings& s) { s.springs.structural = glm::vec2(250.0f); });

    // The next substep runs with it: against the same cloth without gravity, a free corner has fallen in
    // proportion to g (the first substep is linear in gravity).
    const std::size_t corner = sim.particle_count() - 1;
    REQUIRE_FALSE(sim.particle(corner).pinned);
    sim.substep();
    earth.substep();
    weightless.substep();
    const double moon_drop = weightless.position(corner).y - sim.position(corner).y;
    const double earth_drop = weightless.position(corner).y - earth.position(corner).y;
    REQUIRE(earth_drop > 0.0);
    CHECK(moon_drop / earth_drop == Approx(1.62 / 9.81).epsilon(1e-3));

    // Save writes what runs, and the file loads back to exactly those settings.
    const std::filesystem::path path = std::filesystem::temp_directory_path() / "clothsim_running_scene.toml";
    std::ofstream(path) << to_toml(running_scene(document, sim));
    const Scene saved = load_scene(path.string());
    std::filesystem::remove(path);
    CHECK(saved.settings == sim.settings());
    CHECK(saved.settings.springs.structural.x == 250.0f);
    CHECK(saved.cloth.rows == document.cloth.rows);
}

TEST_CASE("a drop opens the first .toml file and refuses every other file, saying why") {
    const clothsim::test::TempDir dir("drop_choice");
    const std::filesystem::path a = dir / "a.toml", b = dir / "b.toml", picture = dir / "cloth.png";
    std::ofstream(a) << "name = \"a\"\n";
    std::ofstream(b) << "name = \"b\"\n";
    std::ofstream(picture) << "not a scene";
    std::filesystem::create_directories(dir / "folder.toml");

    const DropChoice one = choose_dropped_scene({a.string()});
    CHECK(one.open == std::optional<std::string>(a.string()));
    CHECK(one.refused.empty());

    const DropChoice mixed = choose_dropped_scene(
        {picture.string(), (dir / "folder.toml").string(), (dir / "missing.toml").string(), b.string(), a.string()});
    CHECK(mixed.open == std::optional<std::string>(b.string()));
    REQUIRE(mixed.refused.size() == 4);
    CHECK_THAT(mixed.refused[0], Contains("cloth.png") && Contains("not a scene file"));
    CHECK_THAT(mixed.refused[1], Contains("folder.toml") && Contains("a folder"));
    CHECK_THAT(mixed.refused[2], Contains("missing.toml") && Contains("no such file"));
    CHECK_THAT(mixed.refused[3], Contains("a.toml") && Contains("one scene at a time"));

    const DropChoice none = choose_dropped_scene({picture.string()});
    CHECK(!none.open);
    CHECK(none.refused.size() == 1);
}

TEST_CASE("a dropped scene that does not load changes nothing the user has") {
    const clothsim::test::TempDir dir("drop_bad");
    const std::filesystem::path bad = dir / "bad.toml";
    std::ofstream(bad) << "[cloth]\nrows = -4\n";
    Session s;
    const auto positions = s.sim.positions();
    const double time = s.sim.time();
    const DropChoice choice = choose_dropped_scene({bad.string()});
    REQUIRE(choice.open);
    const auto error = open_scene(*choice.open, s.edited, s.loaded, s.sim);  // what the app does with the drop
    REQUIRE(error);
    CHECK_THAT(*error, Contains("bad.toml") && Contains("cloth.rows"));
    check_untouched(s, positions, time);
}

TEST_CASE("a dropped .obj becomes a mesh collider standing on the floor at the given point, a bad one is refused by line") {
    const clothsim::test::TempDir dir("drop_mesh");
    const std::filesystem::path crate = dir / "Crate.OBJ", bad = dir / "bad.obj";
    clothsim::write_mesh_file(clothsim::box_mesh(glm::dvec3(0.4, 0.3, 0.2)), crate, "a crate");
    std::ofstream(bad) << "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n";
    const DropChoice choice = choose_dropped_scene({crate.string(), (dir / "note.txt").string(), bad.string()});
    CHECK(!choice.open);
    CHECK(choice.meshes == std::vector<std::string>{crate.string(), bad.string()});  // the extension in any case
    REQUIRE(choice.refused.size() == 1);
    Session s;
    const std::size_t before = s.sim.settings().colliders.shapes.size();
    const std::string added = add_dropped_mesh(crate.string(), glm::vec3(1.0f, 0.0f, -0.5f), s.sim);
    CHECK_THAT(added, Contains("added") && Contains("12 triangles"));
    REQUIRE(s.sim.settings().colliders.shapes.size() == before + 1);
    const auto& mesh = std::get<clothsim::MeshCollider>(s.sim.settings().colliders.shapes.back().shape);
    CHECK(mesh.position == glm::vec3(1.0f, 0.15f, -0.5f));  // the box's lowest point on the floor, centred there
    CHECK(std::filesystem::path(mesh.file).is_absolute());
    const std::string refused = add_dropped_mesh(bad.string(), glm::vec3(0.0f), s.sim);
    CHECK_THAT(refused, Contains("bad.obj") && Contains(":3") && Contains("not added"));
    CHECK(s.sim.settings().colliders.shapes.size() == before + 1);
}
