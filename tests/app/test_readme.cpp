// The documentation matches the program: README.md names every scene field, every bundled scene and every
// flag that `clothsim --help` lists.
#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

namespace {

std::string readme() {
    std::ifstream in(CLOTHSIM_SOURCE_DIR "/README.md");
    REQUIRE(in);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

}  // namespace

TEST_CASE("readme documents every scene field with its allowed values", "[readme]") {
    const std::string text = readme();
    for (const clothsim::FieldInfo& f : clothsim::scene_fields()) {
        INFO(f.name);
        CHECK(text.find("| `" + std::string(f.name) + "` |") != std::string::npos);
        CHECK(text.find(clothsim::describe_allowed(f)) != std::string::npos);
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
