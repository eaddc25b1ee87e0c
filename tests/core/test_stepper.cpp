// The Stepper: the run policy the app and --headless share (fixed step, frame budget, auto substeps, the
// guard), and results bit-identical to recorded runs.
#include "clothsim/scene.hpp"
#include "clothsim/stepper.hpp"

#include "per_spring_scenes.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>

#include <cstring>
#include <string>

using namespace clothsim;

namespace {

// FNV-1a over the bytes of every position (double, as the state holds them).
unsigned long long position_hash(const MassSpring& sim) {
    unsigned long long h = 1469598103934665603ull;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const glm::dvec3 p = sim.state().position.get(i);
        unsigned char bytes[sizeof p];
        std::memcpy(bytes, &p, sizeof p);
        for (unsigned char c : bytes) {
            h ^= c;
            h *= 1099511628211ull;
        }
    }
    return h;
}

// 60 steps of every bundled scene with MassSpring::run_steps, and with the app's policy (auto substeps at 0.5
// of the critical substep before each step, the guard on). A refactor that changes one is a change of the
// physics.
struct Recorded {
    const char* scene;
    unsigned long long plain, app;
    int app_substeps;
};
// The bundled scenes as shipped, in the material form: recorded when they moved to [material] (issue 14).
constexpr Recorded kRecorded[] = {
    {"curtain", 0xacc0faebd8fbb3a2ull, 0xd7e847ed9f3fe653ull, 86},
    {"drape-cube", 0xfe2347010716328cull, 0x1b59f8542c2fa0c7ull, 191},
    {"drape-sphere", 0xc437c2068af1d711ull, 0x5543ca1879f562adull, 152},
    {"falling", 0xaceda5808e062226ull, 0x54361637248ec069ull, 145},
    {"flag", 0x38c3cb0d417c9180ull, 0xe8fee66fd4a0881bull, 203},  // re-recorded at damping 1.0
    {"hanging", 0x3a45adc47169a47dull, 0xa5dfc886b79ef7d9ull, 145},  // re-recorded with its tethers
    // The stiff scenes (issue 15) on the coarser grid of tests/support.hpp, 24 x 24 (scene_for_loops).
    // stiff-drape runs XPBD's grid form at 32 substeps, which auto substeps keeps (the app's run equals the plain one).
    {"stiff-drape", 0x5af9f8f13b674e56ull, 0x5af9f8f13b674e56ull, 32},
    {"stiff-hanging", 0xa6dce94670bed242ull, 0xf69cdd74d406ac17ull, 197},
};
// The same scenes in the per-spring form they had before (per_spring_scenes.hpp): the hashes recorded when the
// state became double precision (those of the Stepper's introduction, in float, were checked equal to the
// stepping before it; the double state changed every result by design). per_spring_scene() must give them.
constexpr Recorded kRecordedPerSpring[] = {
    {"curtain", 0xa4cb735e6b040b13ull, 0x63579e0b29782917ull, 49},
    {"drape-cube", 0x2e64af28130a5072ull, 0x718de85084f3af83ull, 52},
    {"drape-sphere", 0x56e499723906ce4aull, 0x8ddeeb48bdc4961cull, 52},
    {"falling", 0xaca587f6082446e0ull, 0x02cdb617481cceafull, 46},
    {"flag", 0x0729a1e927678673ull, 0x9d743266f9bf3bdbull, 54},
    {"hanging", 0x25744656afab62b8ull, 0x4ed23c429b6fcc93ull, 46},
};

// The same, 10 steps of drape-sphere in the per-spring form with each other path and integrator.
struct RecordedVariant {
    const char* set;
    unsigned long long plain;
};
constexpr RecordedVariant kRecordedVariants[] = {
    {"solver.method=textbook", 0x165e2d5a3390c29bull},
    {"integration.integrator=symplectic-euler", 0x76d63333460e24dbull},
    {"integration.integrator=rk4", 0x452a836863de066bull},
    {"integration.integrator=implicit-euler", 0x6f877e19b8a5e12bull},
    {"integration.integrator=xpbd", 0x15d991330d40f42bull},  // the grid form (grid_xpbd.hpp)
};

// The hanging cloth in the per-spring form: the run policy does not depend on the form, and these tests
// edit its springs.
MassSpring hanging(float dt = 0.01f) {
    Scene s = per_spring_scene("hanging");
    s.settings.integration.dt = dt;
    return build_simulation(s);
}

}  // namespace

namespace {

void check_recorded(const Recorded& r, const Scene& scene) {
    MassSpring plain = build_simulation(scene);
    plain.run_steps(60);
    CHECK(position_hash(plain) == r.plain);

    RunPolicy policy;
    policy.auto_substeps = true;
    policy.safety = 0.5f;
    policy.guard = true;
    Stepper stepper(policy);
    MassSpring app = build_simulation(scene);
    for (int step = 0; step < 60; ++step) stepper.run(app, 1);
    CHECK(position_hash(app) == r.app);
    CHECK(app.settings().integration.substeps == r.app_substeps);
}

}  // namespace

TEST_CASE("stepper every bundled scene runs bit-identically to the recorded positions", "[stepper]") {
    for (const Recorded& r : kRecorded) {
        INFO("scene " << r.scene);
        check_recorded(r, test::scene_for_loops(r.scene));
    }
    for (const Recorded& r : kRecordedPerSpring) {
        INFO("scene " << r.scene << " in the per-spring form");
        check_recorded(r, per_spring_scene(r.scene));
    }
    for (const RecordedVariant& v : kRecordedVariants) {
        INFO("drape-sphere per spring, " << v.set);
        Scene scene = per_spring_scene("drape-sphere");
        apply_override(scene, v.set);
        MassSpring sim = build_simulation(scene);
        sim.run_steps(10);
        CHECK(position_hash(sim) == v.plain);
    }
}

// Every scene file the project holds, stepped as loaded and with each other path and contact model: hashes
// recorded before the colliders became a list (the mesh scene's when meshes came), so both scene-file forms must load into the same contacts in
// the same order. A refactor that changes one is a change of the physics.
namespace {

struct RecordedFile {
    const char* scene;  // a bundled scene (on the grid of scene_for_loops) or a file in tests/data
    const char* set;    // an override, or "" for the file as it is
    int steps;
    unsigned long long hash;
};
constexpr RecordedFile kRecordedFiles[] = {
    {"cusick", "", 8, 0xceeecdd970734343ull},
    {"fold", "", 30, 0x82dd8e684839d8b7ull},
    {"pile", "", 30, 0x7237926cec285531ull},
    {"tear", "", 30, 0x1f4540ca438bd6edull},
    {"drape-cube", "solver.threads=2", 30, 0xf16548280fbc2b52ull},
    {"scene_small.toml", "", 30, 0x78a660a1bd9fef25ull},
    {"scene_every_collider.toml", "", 60, 0xeb9f03e53281993cull},
    {"scene_every_collider.toml", "solver.threads=2", 60, 0xeb9f03e53281993cull},
    {"scene_every_collider.toml", "solver.method=textbook", 60, 0xeb9f03e53281993cull},
    {"scene_every_collider.toml", "solver.broad_phase=false", 60, 0xeb9f03e53281993cull},
    {"scene_every_collider.toml", "colliders.contact=penalty", 60, 0x34b8a72981c5f1a0ull},
    {"scene_every_collider.toml", "integration.integrator=xpbd", 60, 0xbc6a8e9ec06b4b7aull},
    {"scene_every_collider.toml", "integration.integrator=implicit-euler", 30, 0xb29d1ef0b3b5135aull},
    // A mesh collider (recorded when meshes came): the same contacts on every path and thread count.
    {"tablecloth", "", 40, 0x01eab201b57bd5b6ull},
    {"tablecloth", "solver.threads=2", 40, 0x01eab201b57bd5b6ull},
    {"tablecloth", "solver.method=textbook", 40, 0x01eab201b57bd5b6ull},
    {"tablecloth", "solver.broad_phase=false", 40, 0x01eab201b57bd5b6ull},
    // A kinematic collider (a rolling ball, recorded when colliders came to move): the same contacts on every
    // path and thread count, the broad phase reaching the relative paths' starts.
    {"moving-ball", "", 40, 0x22dc13ea4b81e0a0ull},
    {"moving-ball", "solver.threads=2", 40, 0x22dc13ea4b81e0a0ull},
    {"moving-ball", "solver.method=textbook", 40, 0x22dc13ea4b81e0a0ull},
    {"moving-ball", "solver.broad_phase=false", 40, 0x22dc13ea4b81e0a0ull},
    // A mesh cloth on a mesh collider (recorded when its hinges were calibrated and took the Gaussian-curvature term):
    // the same on every thread count and path.
    {"skirt", "", 10, 0x00d51a318a6bf6e8ull},
    {"skirt", "solver.threads=2", 10, 0x00d51a318a6bf6e8ull},
    {"skirt", "solver.method=textbook", 10, 0x00d51a318a6bf6e8ull},
    {"skirt", "solver.broad_phase=false", 10, 0x00d51a318a6bf6e8ull},
};

}  // namespace

TEST_CASE("stepper every scene file steps bit-identically to the hashes recorded before colliders became a list", "[stepper]") {
    for (const RecordedFile& r : kRecordedFiles) {
        INFO("scene " << r.scene << " " << r.set);
        const std::string name = r.scene;
        Scene scene = name.ends_with(".toml") ? load_scene_file(std::string(CLOTHSIM_TEST_DATA) + "/" + name)
                                              : test::scene_for_loops(name);
        if (*r.set) apply_override(scene, r.set);
        MassSpring sim = build_simulation(scene);
        sim.run_steps(r.steps);
        CHECK(position_hash(sim) == r.hash);
    }
}

TEST_CASE("stepper advance runs whole steps of dt and carries the remainder", "[stepper]") {
    MassSpring sim = hanging(0.01f);
    RunPolicy policy;
    policy.frame_budget = 1e9;  // every step owed runs, however loaded the machine
    Stepper stepper(policy);
    CHECK(stepper.advance(sim, 0.025).steps == 2);  // 5 ms carried
    CHECK(stepper.advance(sim, 0.004).steps == 0);  // 9 ms
    CHECK(stepper.advance(sim, 0.002).steps == 1);  // 11 ms: one step, 1 ms left
    CHECK(sim.time() == Approx(0.03).margin(1e-5));
    stepper.restart();
    CHECK(stepper.advance(sim, 0.0095).steps == 0);  // the 1 ms was forgotten
}

TEST_CASE("stepper advance stops starting steps once its frame budget of wall time is spent, and says how much "
          "time it dropped",
          "[stepper]") {
    MassSpring sim = hanging(0.01f);
    RunPolicy policy;
    policy.frame_budget = 0.0;  // spent by the first step: one step a frame, whatever it costs
    Stepper stepper(policy);
    const StepReport report = stepper.advance(sim, 0.105);  // 10 steps owed (and 5 ms)
    CHECK(report.steps == 1);
    CHECK(report.dropped_seconds == Approx(0.09).margin(1e-9));
    CHECK(sim.time() == Approx(0.01).margin(1e-5));
    CHECK(stepper.advance(sim, 0.0).steps == 0);  // the whole steps were dropped; 5 ms stays owed
    CHECK(stepper.advance(sim, 0.005).steps == 1);

    stepper.set_frame_budget(1e9);  // no budget to speak of: every step owed runs
    const StepReport all = stepper.advance(sim, 0.1);
    CHECK(all.steps == 10);
    CHECK(all.dropped_seconds == 0.0);
    CHECK(sim.time() == Approx(0.12).margin(1e-5));
}

TEST_CASE("stepper auto substeps follows a stiffness change and keeps the substep at the safety fraction",
          "[stepper]") {
    MassSpring sim = hanging(0.01f);
    RunPolicy policy;
    policy.auto_substeps = true;
    policy.safety = 0.5f;
    Stepper stepper(policy);
    stepper.run(sim, 1);
    const int soft = sim.settings().integration.substeps;
    CHECK(sim.substep_length() <= 0.5 * stepper.limit(sim).critical_substep * (1.0 + 1e-6));

    test::edit_settings(sim, [](SimulationSettings& s) { s.springs.structural *= 16.0f; });
    stepper.run(sim, 1);
    const int stiff = sim.settings().integration.substeps;
    CHECK(stiff > soft);
    CHECK(sim.substep_length() <= 0.5 * stepper.limit(sim).critical_substep * (1.0 + 1e-6));
    CHECK(sim.substep_length() > 0.25 * stepper.limit(sim).critical_substep);  // not far below it either

    stepper.set_auto_substeps(false);
    test::edit_settings(sim, [](SimulationSettings& s) { s.springs.structural /= 16.0f; });
    stepper.run(sim, 1);
    CHECK(sim.settings().integration.substeps == stiff);  // off: the substeps stay as they are
}

TEST_CASE("stepper auto substeps keeps the substeps of an integrator stable at large steps, and raises them to its "
          "limit", "[stepper]") {
    RunPolicy policy;
    policy.auto_substeps = true;
    policy.safety = 0.5f;
    for (Integrator integrator : {Integrator::Xpbd, Integrator::ImplicitEuler, Integrator::Projective}) {
        INFO(integrator_names()[static_cast<int>(integrator)]);
        Scene s = per_spring_scene("hanging");
        s.cloth.rows = s.cloth.cols = 12;
        s.settings.integration.integrator = integrator;
        s.settings.integration.substeps = 24;  // the scene's choice of accuracy
        MassSpring sim = build_simulation(s);
        Stepper stepper(policy);
        REQUIRE(auto_substeps(stepper.limit(sim), s.settings.integration.dt, policy.safety) < 24);
        stepper.run(sim, 1);
        CHECK(sim.settings().integration.substeps == 24);  // not lowered to what stability alone allows
        // A damping whose explicit decay needs more (XPBD's prediction: c h < 2) raises them.
        if (integrator == Integrator::Xpbd) {
            test::edit_settings(sim, [](SimulationSettings& settings) { settings.springs.damping = 5000.0f; });
            stepper.run(sim, 1);
            CHECK(sim.settings().integration.substeps > 24);
            CHECK(sim.substep_length() <= 0.5 * stepper.limit(sim).critical_substep * (1.0 + 1e-6));
        }
    }
    // Verlet's substeps follow its limit both ways, as before.
    Scene s = per_spring_scene("hanging");
    s.settings.integration.substeps = 2000;
    MassSpring sim = build_simulation(s);
    Stepper stepper(policy);
    stepper.run(sim, 1);
    CHECK(sim.settings().integration.substeps < 2000);
}

TEST_CASE("stepper the guard doubles the substeps of a step that blew up and turns auto substeps off",
          "[stepper]") {
    Scene scene = per_spring_scene("hanging");
    scene.settings.integration.substeps = 1;  // 16.7 ms against a critical substep near 0.6 ms: blows up
    MassSpring sim = build_simulation(scene);
    RunPolicy policy;
    policy.guard = true;
    Stepper stepper(policy);
    const StepReport report = stepper.run(sim, 3);
    CHECK(report.steps == 3);
    CHECK_FALSE(report.guard_gave_up);
    CHECK(sim.all_finite());
    CHECK(sim.settings().integration.substeps > 8);
    CHECK(report.guard_log.find("at 1 substeps; rolled back, it held at " +
                                std::to_string(sim.settings().integration.substeps)) != std::string::npos);

    // With auto substeps on, the guard's choice stays: auto substeps turns itself off and says so.
    MassSpring strict = build_simulation(per_spring_scene("hanging"));
    RunPolicy strict_policy;
    strict_policy.auto_substeps = true;
    strict_policy.guard = true;
    strict_policy.guard_settings.max_strain = 1e-9f;  // any stretch counts as a blow-up
    strict_policy.guard_settings.max_retries = 1;
    Stepper strict_stepper(strict_policy);
    const StepReport gave_up = strict_stepper.run(strict, 1);
    CHECK(gave_up.guard_gave_up);
    // Nothing held, so the guard chose no substeps: auto substeps stays on, and the log says no such thing.
    CHECK(strict_stepper.policy().auto_substeps);
    CHECK(gave_up.guard_log.find("auto substeps turned off") == std::string::npos);
    CHECK(strict.all_finite());
}

TEST_CASE("stepper a non-finite cloth is not stepped", "[stepper]") {
    MassSpring sim = hanging();
    sim.set_particle(sim.particle_count() - 1, glm::vec3(NAN), glm::vec3(0.0f));
    Stepper stepper;
    const double time = sim.time();
    const StepReport report = stepper.run(sim, 2);
    CHECK(report.skipped_non_finite);
    CHECK(report.steps == 0);
    CHECK(sim.time() == time);
}
