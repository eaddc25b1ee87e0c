// Fuzz target: the scene file loader. Any bytes go to parse_scene(); SceneError is the only allowed failure
// and its message names the source. An accepted scene must validate, round-trip through to_toml() and, when
// small, build and step without crashing (fuzz_support.hpp). Built two ways (tests/fuzz/CMakeLists.txt):
// with libFuzzer (scripts/fuzz) and with replay_main.cpp as a ctest over tests/fuzz/corpus/scene/.
#include "fuzz_support.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace clothsim;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    Scene scene;
    try {
        fuzz::only_scene_errors("parse_scene", [&] { scene = parse_scene(text, "fuzz.toml"); });
    } catch (const SceneError& e) {
        if (!std::string_view(e.what()).starts_with("fuzz.toml")) {
            fuzz::fail("a parse_scene() error does not name its source", e.what());
        }
        return 0;
    }
    fuzz::check_accepted(scene);
    fuzz::simulate_small(scene);
    return 0;
}
