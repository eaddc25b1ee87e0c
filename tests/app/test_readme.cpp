// The documentation matches the program: docs/SCENE_FILES.md names every scene field and every collider kind's
// fields with their allowed values; README.md every bundled scene and every flag that `clothsim --help` lists.
#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

namespace {

std::string read(const char* path) {
    std::ifstream in(std::string(CLOTHSIM_SOURCE_DIR) + "/" + path);
    REQUIRE(in);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::string readme() { return read("README.md"); }

}  // namespace

TEST_CASE("readme the scene-file reference documents every scene field and collider field with its allowed values", "[readme]") {
    const std::string text = read("docs/SCENE_FILES.md");
    for (const clothsim::FieldInfo& f : clothsim::scene_fields()) {
        INFO(f.name);
        CHECK(text.find("| `" + std::string(f.name) + "` |") != std::string::npos);
        CHECK(text.find(clothsim::describe_allowed(f)) != std::string::npos);
    }
    for (std::size_t kind = 0; kind < clothsim::kColliderKindCount; ++kind) {
        const std::string name(clothsim::collider_kind_names()[kind]);
        for (const clothsim::ColliderField& f : clothsim::collider_fields_of_kind(kind)) {
            INFO(name << "." << f.name);
            const std::string row = "| `" + name + "` | `" + std::string(f.name) + "` |";
            const auto at = text.find(row);
            REQUIRE(at != std::string::npos);
            CHECK(text.substr(at, text.find('\n', at) - at).find(clothsim::describe_allowed(f)) != std::string::npos);
        }
    }
}

TEST_CASE("readme lists every bundled scene and flag", "[readme]") {
    const std::string text = readme();
    for (const std::string& name : clothsim::bundled_scene_names()) {
        INFO(name);
        CHECK(text.find("| `" + name + "` |") != std::string::npos);
    }
    for (const char* flag : {"--headless", "--scene", "--duration", "--steps", "--set", "--trajectory", "--every",
                             "--obj", "--json", "--list-scenes", "--list-fields", "--print-scene", "--frames", "--screenshot",
                             "--size", "--view", "--auto-substeps", "--guard", "--version", "--record"}) {
        INFO(flag);
        CHECK(text.find(std::string("`") + flag) != std::string::npos);
    }
    CHECK(text.find("scripts/run") != std::string::npos);
    CHECK(text.find("scripts/test") != std::string::npos);
}
