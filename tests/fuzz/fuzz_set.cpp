// Fuzz target: `--set key=value` overrides. The bytes are split on '\n' into up to 4 assignments applied
// in turn to a small fixed scene (no file I/O). SceneError is the only allowed failure; it names the --set
// flag and leaves the scene unchanged. After each accepted assignment the scene must validate and
// round-trip through to_toml(); at the end a small cloth is built and stepped (fuzz_support.hpp).
#include "fuzz_support.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace {

constexpr std::string_view kBase = R"(name = "fuzz-base"
description = "small cloth the --set fuzzer starts from"
pins = "top-corners"

[cloth]
rows = 8
cols = 8
size = [1.0, 1.0]
origin = [-0.5, 1.5, 0.0]

[colliders.sphere]
enabled = true

[integration]
substeps = 4
)";

const clothsim::Scene& base_scene() {
    static const clothsim::Scene scene = clothsim::parse_scene(kBase, "fuzz-base.toml");
    return scene;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace clothsim;
    std::string_view rest(reinterpret_cast<const char*>(data), size);
    Scene scene = base_scene();
    for (int i = 0; i < 4 && !rest.empty(); ++i) {
        const std::size_t newline = rest.find('\n');
        const std::string_view assignment = rest.substr(0, newline);
        rest = newline == std::string_view::npos ? std::string_view{} : rest.substr(newline + 1);

        const std::string before = to_toml(scene);
        try {
            fuzz::only_scene_errors("apply_override", [&] { apply_override(scene, assignment); });
        } catch (const SceneError& e) {
            if (!std::string_view(e.what()).starts_with("--set ")) {
                fuzz::fail("an apply_override() error does not name the --set flag", e.what());
            }
            const std::string after = to_toml(scene);
            if (after != before) fuzz::fail("a rejected --set changed the scene", before, after);
            continue;
        }
        fuzz::check_accepted(scene);
    }
    fuzz::simulate_small(scene);
    return 0;
}
