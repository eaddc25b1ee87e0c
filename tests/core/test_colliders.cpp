// Colliders: no free particle ends a step inside the sphere, the box or below the ground; Coulomb friction.
#include "support.hpp"

#include "clothsim/colliders.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>

using namespace clothsim;

namespace {

// Smallest signed distance of a free particle to each enabled collider (m).
struct Clearance {
    float sphere = INFINITY, cube = INFINITY, ground = INFINITY;
};

Clearance clearance(const MassSpring& sim) {
    Clearance c;
    const ColliderSettings& col = sim.settings().colliders;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        if (sim.particle(i).pinned) continue;
        const glm::vec3 p = sim.position(i);
        if (col.sphere.enabled) c.sphere = std::min(c.sphere, signed_distance(col.sphere, p));
        if (col.cube.enabled) c.cube = std::min(c.cube, signed_distance(col.cube, p));
        if (col.ground.enabled) c.ground = std::min(c.ground, signed_distance(col.ground, p));
    }
    return c;
}

// One free particle resting on the ground (at the skin distance), sliding along x at `speed`.
MassSpring slider(float friction, float speed) {
    Scene s = test::chain(1, 1.0f, 0.1f, 0.0f);
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.colliders.ground = {true, 0.0f, friction};
    s.settings.colliders.thickness = 0.005f;
    s.cloth.origin = {0.0f, 0.005f, 0.0f};
    s.cloth.velocity = {speed, 0.0f, 0.0f};
    s.settings.integration.dt = 1.0f / 60.0f;
    s.settings.integration.substeps = 20;
    return build_simulation(s);
}

}  // namespace

TEST_CASE("colliders no free particle ends a step inside the sphere, the cube or below the ground", "[colliders]") {
    for (const char* name : {"drape-sphere", "drape-cube", "falling"}) {
        MassSpring sim = build_simulation(load_scene(name));
        Clearance worst;
        long long contacts = 0;
        for (int step = 0; step < 180; ++step) {  // 3 s: falls, hits, drapes, settles
            sim.run_steps(1);
            const Clearance c = clearance(sim);
            worst.sphere = std::min(worst.sphere, c.sphere);
            worst.cube = std::min(worst.cube, c.cube);
            worst.ground = std::min(worst.ground, c.ground);
            contacts += (c.sphere < 0.01f) + (c.cube < 0.01f) + (c.ground < 0.01f);
        }
        INFO(name << ": smallest clearance sphere " << worst.sphere << ", cube " << worst.cube << ", ground "
                  << worst.ground);
        CHECK(worst.sphere >= 0.0f);
        CHECK(worst.cube >= 0.0f);
        CHECK(worst.ground >= 0.0f);
        CHECK(contacts > 0);  // the cloth really touched something
    }
}

TEST_CASE("colliders push particles out along the shortest way", "[colliders]") {
    State st;
    st.position.resize(4);
    st.motion.resize(4);
    st.pinned = {0, 0, 0, 1};
    st.position.set(0, {0.0f, 0.9f, 0.0f});   // just inside the top face of the unit box at y = 0.5 +- 0.5
    st.position.set(1, {0.45f, 0.5f, 0.1f});  // nearest the +x face
    st.position.set(2, {0.0f, 0.2f, -0.48f}); // nearest the -z face
    st.position.set(3, {0.0f, 0.5f, 0.0f});   // pinned: never moved, even inside
    const CubeCollider cube{true, {0.0f, 0.5f, 0.0f}, {1.0f, 1.0f, 1.0f}, 0.0f};
    collide(st, cube, 0.01f);
    CHECK(st.position.get(0).y == Approx(1.01f));
    CHECK(st.position.get(0).x == 0.0f);
    CHECK(st.position.get(1).x == Approx(0.51f));
    CHECK(st.position.get(1).y == 0.5f);
    CHECK(st.position.get(2).z == Approx(-0.51f));
    CHECK(st.position.get(3) == glm::dvec3(0.0, 0.5, 0.0));
    // The push moves the particle but gives it no velocity: a deep penetration must not launch it.
    CHECK(st.motion.get(0) == glm::dvec3(0.0));
    // Inward motion is removed (inelastic), outward and tangential motion kept when frictionless.
    st.position.set(0, {0.1f, 0.95f, 0.0f});
    st.motion.set(0, {0.02f, -0.01f, 0.0f});
    collide(st, cube, 0.01f);
    CHECK(st.motion.get(0).x == Approx(0.02f));
    CHECK(st.motion.get(0).y == 0.0f);
    st.position.set(0, {0.1f, 0.95f, 0.0f});
    st.motion.set(0, {0.0f, 0.03f, 0.0f});  // already leaving: keeps its outward motion
    collide(st, cube, 0.01f);
    CHECK(st.motion.get(0).y == Approx(0.03f));

    st.position.set(0, {0.3f, 0.4f, 0.0f});  // inside the sphere of radius 1 at the origin
    collide(st, SphereCollider{true, {0.0f, 0.0f, 0.0f}, 1.0f, 0.0f}, 0.0f);
    CHECK(glm::length(st.position.get(0)) == Approx(1.0f));
    CHECK(st.position.get(0).x == Approx(0.6f));
    CHECK(st.position.get(0).y == Approx(0.8f));
}

TEST_CASE("colliders friction 0 keeps tangential motion", "[colliders]") {
    MassSpring sim = slider(0.0f, 2.0f);
    sim.run_steps(60);  // 1 s on the ground
    CHECK(sim.position(0).x == Approx(2.0f).epsilon(1e-4));
    CHECK(sim.velocities()[0].x == Approx(2.0f).epsilon(1e-4));
    CHECK(sim.position(0).y >= 0.0f);
}

TEST_CASE("colliders friction > 0 slows sliding at mu g and stops it at v^2 / (2 mu g)", "[colliders]") {
    for (float mu : {0.2f, 0.5f, 1.0f}) {
        const float v0 = 2.0f;
        MassSpring sim = slider(mu, v0);
        const double stop_time = v0 / (mu * 9.81);
        sim.run_steps(static_cast<long long>(std::ceil(0.5 * stop_time * 60)));
        // While sliding, Coulomb friction decelerates at mu g: v = v0 - mu g t.
        CHECK(sim.velocities()[0].x == Approx(v0 - mu * 9.81 * sim.time()).epsilon(0.02));
        sim.run_steps(static_cast<long long>(std::ceil(stop_time * 60)));
        const double distance = v0 * v0 / (2.0 * mu * 9.81);
        INFO("mu " << mu << ": stopped after " << sim.position(0).x << " m, expected " << distance);
        CHECK(sim.position(0).x == Approx(distance).epsilon(0.005));
        CHECK(std::fabs(sim.velocities()[0].x) < 1e-3);
    }
}

TEST_CASE("colliders signed distances", "[colliders]") {
    const SphereCollider sphere{true, {1.0f, 0.0f, 0.0f}, 0.5f, 0.0f};
    CHECK(signed_distance(sphere, {1.0f, 0.0f, 0.0f}) == Approx(-0.5f));
    CHECK(signed_distance(sphere, {1.0f, 2.0f, 0.0f}) == Approx(1.5f));
    const CubeCollider cube{true, {0.0f, 0.0f, 0.0f}, {2.0f, 2.0f, 2.0f}, 0.0f};
    CHECK(signed_distance(cube, {0.0f, 0.0f, 0.0f}) == Approx(-1.0f));
    CHECK(signed_distance(cube, {0.0f, 0.5f, 0.0f}) == Approx(-0.5f));
    CHECK(signed_distance(cube, {2.0f, 2.0f, 1.0f}) == Approx(std::sqrt(2.0f)));
    CHECK(signed_distance(GroundCollider{true, -1.0f, 0.0f}, {5.0f, 1.0f, 5.0f}) == Approx(2.0f));
}

TEST_CASE("colliders a particle too fast for one substep does not pass through the sphere or the cube",
          "[colliders]") {
    // 2 m in one substep straight through the middle of each (radius 0.3, a 0.4 m box): without a swept test
    // it ends outside on the far side, untouched.
    SphereCollider sphere;
    sphere.enabled = true;
    sphere.center = {0.0f, 0.0f, 0.0f};
    sphere.radius = 0.3f;
    CubeCollider cube;
    cube.enabled = true;
    cube.center = {0.0f, 0.0f, 0.0f};
    cube.size = {0.4f, 0.4f, 0.4f};
    const float thickness = 0.01f;
    for (int shape = 0; shape < 2; ++shape) {
        INFO((shape == 0 ? "sphere" : "cube"));
        // Ends 1 m past the centre (outside), and 0.05 m past it (inside, nearest way out the far side).
        for (float end : {1.0f, 0.05f}) {
            INFO("ends at x = " << end);
            State st = test::free_particles({{end, 0.0f, 0.0f}}, 0.01f);
            st.motion.set(0, {end + 1.0f, 0.0f, 0.0f});  // came from x = -1
            if (shape == 0) collide(st, sphere, thickness);
            else collide(st, cube, thickness);
            const float face = shape == 0 ? sphere.radius : 0.5f * cube.size.x;
            CHECK(st.position.get(0).x == Approx(-(face + thickness)).margin(1e-5));  // stopped at the near side
            CHECK(st.motion.get(0).x == Approx(0.0f).margin(1e-6));                   // its inward motion gone
        }
    }
    // A glancing path that stays in the thickness shell (a particle sliding over the top) is not a pass.
    State slide = test::free_particles({{0.01f, sphere.radius + thickness, 0.0f}}, 0.01f);
    slide.motion.set(0, {0.02f, 0.0f, 0.0f});
    collide(slide, sphere, thickness);
    CHECK(slide.position.get(0).x == Approx(0.01f));
}

TEST_CASE("colliders implicit Euler and XPBD at dt 0.1 with 1 substep drape the cloth on the sphere", "[colliders]") {
    for (const char* integrator : {"implicit-euler", "xpbd"}) {
        INFO(integrator);
        Scene scene = load_scene("drape-sphere");
        apply_override(scene, std::string("integration.integrator=") + integrator);
        scene.settings.integration.dt = 0.1f;
        scene.settings.integration.substeps = 1;
        MassSpring sim = build_simulation(scene);
        sim.run_steps(30);  // 3 s
        REQUIRE(sim.all_finite());
        const SphereCollider& sphere = scene.settings.colliders.sphere;
        // The cloth lies on the sphere, not on the ground below it, and no particle is inside it.
        float highest = -1e9f;
        for (std::size_t i = 0; i < sim.particle_count(); ++i) highest = std::max(highest, sim.position(i).y);
        CHECK(highest > sphere.center.y + 0.9f * sphere.radius);
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            CHECK(signed_distance(sphere, sim.position(i)) > -1e-3f);
        }
    }
}
