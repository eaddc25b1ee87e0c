// Shared checks of the two fuzz targets (fuzz_scene.cpp, fuzz_set.cpp). Every broken promise aborts with a
// message on stderr, so libFuzzer (and the replay driver under ctest) reports the input as a crash.
#pragma once

#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>

namespace clothsim::fuzz {

[[noreturn]] inline void fail(std::string_view what, std::string_view detail = {}, std::string_view more = {}) {
    std::fprintf(stderr, "\nFUZZ CHECK FAILED: %.*s\n", static_cast<int>(what.size()), what.data());
    if (!detail.empty()) std::fprintf(stderr, "---\n%.*s\n", static_cast<int>(detail.size()), detail.data());
    if (!more.empty()) std::fprintf(stderr, "---\n%.*s\n", static_cast<int>(more.size()), more.data());
    std::fflush(stderr);
    std::abort();
}

// Anything but SceneError escaping the scene code is a bug: report it with its message.
template <class F>
void only_scene_errors(std::string_view where, F&& body) {
    try {
        body();
    } catch (const SceneError&) {
        throw;
    } catch (const std::exception& e) {
        fail(std::string(where) + " threw a non-SceneError exception", e.what());
    } catch (...) {
        fail(std::string(where) + " threw a non-std::exception");
    }
}

inline bool same_scene(const Scene& a, const Scene& b) {
    const ClothSettings &x = a.cloth, &y = b.cloth;
    return a.name == b.name && a.description == b.description && x.rows == y.rows && x.cols == y.cols &&
           x.size == y.size && x.mass == y.mass && x.origin == y.origin && x.u_axis == y.u_axis &&
           x.v_axis == y.v_axis && x.velocity == y.velocity && a.pins == b.pins && a.settings == b.settings;
}

// A scene the loader accepted: validate() agrees, and to_toml() reads back to the same scene (field by
// field, and the text is a fixed point).
inline void check_accepted(const Scene& scene) {
    try {
        only_scene_errors("validate", [&] { validate(scene); });
    } catch (const SceneError& e) {
        fail("validate() rejects a scene the loader accepted", e.what(), to_toml(scene));
    }
    const std::string text = to_toml(scene);
    Scene back;
    try {
        only_scene_errors("parse_scene(to_toml(scene))", [&] { back = parse_scene(text, "round-trip"); });
    } catch (const SceneError& e) {
        fail("parse_scene(to_toml(scene)) throws", e.what(), text);
    }
    const std::string again = to_toml(back);
    if (again != text) fail("to_toml(parse_scene(to_toml(scene))) != to_toml(scene)", text, again);
    if (!same_scene(scene, back)) fail("parse_scene(to_toml(scene)) differs from scene", text, again);
}

// Builds small cloths and steps them. Capped so one input stays fast under the sanitizers: at most 4096
// particles, 4 substeps a step, 2 threads. The guard's promise is checked: it never leaves NaN.
inline void simulate_small(Scene scene) {
    if (static_cast<long long>(scene.cloth.rows) * scene.cloth.cols > 4096) return;
    auto& integration = scene.settings.integration;
    integration.substeps = std::min(integration.substeps, 4);
    scene.settings.solver.threads = std::min(scene.settings.solver.threads, 2);
    try {
        only_scene_errors("build_simulation", [&] {
            MassSpring sim = build_simulation(scene);
            if (!sim.all_finite()) fail("build_simulation() made non-finite positions", to_toml(scene));
            std::string log;
            GuardSettings guard;
            guard.max_retries = 2;
            run_guarded(sim, 1, guard, log);
            if (!sim.all_finite()) fail("run_guarded() left non-finite positions", log, to_toml(scene));
            // Unguarded: the state may blow up (stiff springs, long substeps), it must not crash.
            for (int i = 0; i < 3; ++i) sim.substep();
            (void)max_strain(sim);
            (void)sim.energy();
        });
    } catch (const SceneError& e) {
        fail("build_simulation() rejects a scene validate() accepted", e.what(), to_toml(scene));
    }
}

}  // namespace clothsim::fuzz
