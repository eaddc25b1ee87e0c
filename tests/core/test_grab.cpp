// The user's grab (MassSpring::grab): a stiff, damped, force-limited spring from a particle to the mouse.
// A hard drag pulls the cloth along instead of tearing one particle into a spike that the guard then takes
// for a blow-up.
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"
#include "clothsim/stepper.hpp"

#include "per_spring_scenes.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>

#include <glm/geometric.hpp>

#include <string>

using namespace clothsim;

namespace {

// The app's policy: auto substeps at 0.5 of the critical substep, the guard on.
Stepper app_stepper() {
    RunPolicy policy;
    policy.auto_substeps = true;
    policy.safety = 0.5f;
    policy.guard = true;
    return Stepper(policy);
}

struct Drag {
    std::string log;
    bool gave_up = false;
    double worst_strain = 0.0;  // over the springs not attached to the grabbed particle
    float final_distance = 0.0f;  // m: grabbed particle to the target at the end
};

// Grabs particle `i` and moves the target by `pull` over `frames` steps (a fast mouse), then holds it for
// `hold` steps.
Drag drag(MassSpring& sim, std::size_t i, glm::vec3 pull, int frames, int hold) {
    Stepper stepper = app_stepper();
    const glm::vec3 start = sim.position(i);
    Drag d;
    for (int f = 1; f <= frames + hold; ++f) {
        const glm::vec3 target = start + pull * (float(std::min(f, frames)) / float(frames));
        sim.grab(i, target);
        const StepReport r = stepper.run(sim, 1);
        d.log += r.guard_log;
        d.gave_up |= r.guard_gave_up;
        d.worst_strain = std::max(d.worst_strain, max_strain(sim));
        d.final_distance = glm::length(sim.position(i) - target);
    }
    return d;
}

}  // namespace

TEST_CASE("grab a hard drag of curtain pulls the cloth along: no guard retry, bounded strain", "[grab]") {
    MassSpring sim = build_simulation(load_scene("curtain"));
    const std::size_t middle = sim.particle_count() / 2 + static_cast<std::size_t>(sim.topology().cols / 2);
    REQUIRE_FALSE(sim.particle(middle).pinned);
    // 1.5 m toward the camera in 6 frames (0.1 s): the 400 px flick that used to wedge the app.
    const Drag d = drag(sim, middle, {0.0f, 0.0f, 1.5f}, 6, 54);
    INFO(d.log);
    CHECK(d.log.empty());
    CHECK_FALSE(d.gave_up);
    CHECK(sim.all_finite());
    CHECK(d.worst_strain < 1.0);        // the rest of the cloth stays within 100% strain
    CHECK(d.final_distance < 1.0f);     // and the grabbed particle has come a third of the way, against the pins
    CHECK(glm::length(sim.grab_force()) <= sim.grab_force_limit() * (1.0f + 1e-5f));
}

TEST_CASE("grab a drag with structural and shear at 0, and of a 2048 x 1 chain, never trips the guard", "[grab]") {
    SECTION("bending springs only") {
        Scene scene = per_spring_scene("curtain");  // skip-one bending springs: a per-spring topology
        scene.settings.springs.structural = glm::vec2(0.0f);
        scene.settings.springs.shear = 0.0f;
        MassSpring sim = build_simulation(scene);
        const Drag d = drag(sim, sim.particle_count() / 2, {0.0f, 0.0f, 1.5f}, 6, 30);
        INFO(d.log);
        CHECK(d.log.empty());
        CHECK(sim.all_finite());
    }
    SECTION("a long chain") {
        Scene scene = per_spring_scene("hanging");  // a material needs cells: a chain is per spring
        scene.cloth.rows = 2048;
        scene.cloth.cols = 1;
        scene.cloth.size = {0.01f, 2.0f};
        MassSpring sim = build_simulation(scene);
        const Drag d = drag(sim, 1024, {1.0f, 0.0f, 0.0f}, 6, 10);
        INFO(d.log);
        CHECK(d.log.empty());
        CHECK(sim.all_finite());
    }
}

TEST_CASE("grab the force is a damped spring to the target, capped, and gone on release", "[grab]") {
    MassSpring sim = build_simulation(load_scene("hanging"));
    const std::size_t i = sim.particle_count() - 1;
    const glm::vec3 at = sim.position(i);
    sim.grab(i, at + glm::vec3(0.0f, 0.0f, 1e-4f));  // a small pull: below the cap, along +z
    const glm::vec3 small = sim.grab_force();
    const float h = sim.substep_length();
    const float k = 0.25f * sim.particle(i).mass / (h * h);
    CHECK(small.z == Approx(k * 1e-4f).epsilon(1e-3));
    CHECK(std::abs(small.x) < 1e-6f * std::abs(small.z));
    sim.grab(i, at + glm::vec3(0.0f, 0.0f, 100.0f));  // far: the cap
    CHECK(glm::length(sim.grab_force()) == Approx(sim.grab_force_limit()).epsilon(1e-5));
    CHECK(sim.grabbed() == i);
    sim.release_grab();
    CHECK_FALSE(sim.grabbed());
    CHECK(glm::length(sim.grab_force()) == 0.0f);
    // A pinned particle is not grabbed (the app moves the pin instead).
    for (std::size_t p = 0; p < sim.particle_count(); ++p) {
        if (!sim.particle(p).pinned) continue;
        sim.grab(p, sim.position(p) + glm::vec3(1.0f));
        CHECK_FALSE(sim.grabbed());
        break;
    }
}

TEST_CASE("grab every integrator and solver path feels the grab", "[grab]") {
    for (const char* set : {"solver.method=fast", "solver.method=textbook", "integration.integrator=symplectic-euler",
                            "integration.integrator=rk4", "integration.integrator=implicit-euler",
                            "integration.integrator=xpbd"}) {
        INFO(set);
        Scene scene = per_spring_scene("hanging");  // 34 substeps a step: implicit Euler's solves stay cheap
        apply_override(scene, set);
        MassSpring pulled = build_simulation(scene);
        MassSpring free = pulled;
        const std::size_t i = pulled.particle_count() - 1;
        const glm::vec3 target = pulled.position(i) + glm::vec3(0.0f, 0.0f, 0.2f);
        for (int s = 0; s < 10; ++s) {
            pulled.grab(i, target);
            pulled.run_steps(1);
            free.run_steps(1);
        }
        CHECK(pulled.position(i).z - free.position(i).z > 0.02f);  // pulled toward +z
    }
}
