// open_scene: what the panel's Open does. A rejected file changes nothing the user has.
#include "scene_loading.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

using namespace clothsim;
using Catch::Matchers::Contains;

namespace {

const std::filesystem::path kData = CLOTHSIM_TEST_DATA;

struct Session {
    Scene edited, loaded;
    MassSpring sim;
    Session() : edited(load_scene("hanging")), loaded(edited), sim(build_simulation(edited)) {
        edited.settings.springs.structural = 123.0f;  // the user's edit, not yet saved
        sim.run_steps(3);
    }
};

void check_untouched(const Session& s, const std::vector<glm::vec3>& positions, double time) {
    CHECK(s.edited.settings.springs.structural == 123.0f);
    CHECK(s.loaded.settings.springs.structural == 400.0f);
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
