// Colliders: no free particle ends a step inside the sphere, the box, the cylinder or below the ground; the
// shortest way out (the cylinder's faces, side and rims); continuous collision; Coulomb friction.
#include "every_kernel.hpp"
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "clothsim/mesh_shapes.hpp"
#include "collision/colliders.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <variant>

using namespace clothsim;

namespace {

// A collider of `shape`, switched on and frictionless.
template <class Shape>
Collider frictionless(const Shape& shape) {
    return Collider{shape, 0.0f, true, {}};
}

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
        for (const Collider& collider : col.shapes) {
            if (!collider.enabled) continue;
            const float d = signed_distance(collider, p);
            if (std::holds_alternative<SphereCollider>(collider.shape)) c.sphere = std::min(c.sphere, d);
            if (std::holds_alternative<BoxCollider>(collider.shape)) c.cube = std::min(c.cube, d);
            if (std::holds_alternative<PlaneCollider>(collider.shape)) c.ground = std::min(c.ground, d);
        }
    }
    return c;
}

// One free particle resting on the ground (at the skin distance), sliding along x at `speed`.
MassSpring slider(float friction, float speed) {
    Scene s = test::chain(1, 1.0f, 0.1f, 0.0f);
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    test::collider(s.settings.colliders, "ground") = Collider{PlaneCollider{0.0f}, friction, true, {}};
    s.settings.colliders.thickness = 0.005f;
    s.cloth.origin = {0.0f, 0.005f, 0.0f};
    s.cloth.velocity = {speed, 0.0f, 0.0f};
    s.settings.integration.dt = 1.0f / 60.0f;
    s.settings.integration.substeps = 20;
    return build_simulation(s);
}

// The Cusick drape tester's support (ISO 9073-9, BS 5058: an 18 cm disc), here a solid cylinder 0.3 m tall
// standing on y = 0.1; its top face is at y = 0.4.
Collider support(float friction) {
    return Collider{CylinderCollider{{0.1f, 0.25f, -0.2f}, 0.09f, 0.3f}, friction, true, {}};
}

// One free particle at `start` moving at `velocity`, with gravity, no ground, `substeps` per 1/60 s step.
Scene lone_particle(glm::vec3 start, glm::vec3 velocity, int substeps) {
    Scene s = test::chain(1, 1.0f, 0.1f, 0.0f);
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.colliders.thickness = 0.005f;
    s.cloth.origin = start;
    s.cloth.velocity = velocity;
    s.settings.integration.dt = 1.0f / 60.0f;
    s.settings.integration.substeps = substeps;
    s.settings.solver.sleep_speed = 0.0f;
    return s;
}

// Whether two arrays hold the same bits (NaN included).
bool same_bits(const DVec3Array& a, const DVec3Array& b) {
    auto same = [](const auto& u, const auto& v) {
        return u.size() == v.size() && std::memcmp(u.data(), v.data(), u.size() * sizeof(double)) == 0;
    };
    return same(a.x, b.x) && same(a.y, b.y) && same(a.z, b.z);
}

// drape-sphere with a cylinder where the sphere was, its top face where the sphere's top is (per spring, 38
// substeps a step: implicit Euler's 180 steps stay short).
Scene drape_on_cylinder() {
    Scene s = per_spring_scene("drape-sphere");
    test::collider(s.settings.colliders, "sphere").enabled = false;
    test::collider(s.settings.colliders, "cylinder") = Collider{CylinderCollider{{0.0f, 0.425f, 0.0f}, 0.3f, 0.85f}, 0.4f, true, {}};
    return s;
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
    const Collider cube = frictionless(BoxCollider{{0.0f, 0.5f, 0.0f}, {1.0f, 1.0f, 1.0f}});
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
    collide(st, frictionless(SphereCollider{{0.0f, 0.0f, 0.0f}, 1.0f}), 0.0f);
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
    const SphereCollider sphere{{1.0f, 0.0f, 0.0f}, 0.5f};
    CHECK(signed_distance(sphere, {1.0f, 0.0f, 0.0f}) == Approx(-0.5f));
    CHECK(signed_distance(sphere, {1.0f, 2.0f, 0.0f}) == Approx(1.5f));
    const BoxCollider cube{{0.0f, 0.0f, 0.0f}, {2.0f, 2.0f, 2.0f}};
    CHECK(signed_distance(cube, {0.0f, 0.0f, 0.0f}) == Approx(-1.0f));
    CHECK(signed_distance(cube, {0.0f, 0.5f, 0.0f}) == Approx(-0.5f));
    CHECK(signed_distance(cube, {2.0f, 2.0f, 1.0f}) == Approx(std::sqrt(2.0f)));
    CHECK(signed_distance(PlaneCollider{-1.0f}, {5.0f, 1.0f, 5.0f}) == Approx(2.0f));
}

TEST_CASE("colliders a particle too fast for one substep does not pass through the sphere or the cube",
          "[colliders]") {
    // 2 m in one substep straight through the middle of each (radius 0.3, a 0.4 m box): without a swept test
    // it ends outside on the far side, untouched.
    SphereCollider sphere;
    sphere.center = {0.0f, 0.0f, 0.0f};
    sphere.radius = 0.3f;
    BoxCollider cube;
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
            if (shape == 0) collide(st, Collider::of(sphere), thickness);
            else collide(st, Collider::of(cube), thickness);
            const float face = shape == 0 ? sphere.radius : 0.5f * cube.size.x;
            CHECK(st.position.get(0).x == Approx(-(face + thickness)).margin(1e-5));  // stopped at the near side
            CHECK(st.motion.get(0).x == Approx(0.0f).margin(1e-6));                   // its inward motion gone
        }
    }
    // A glancing path that stays in the thickness shell (a particle sliding over the top) is not a pass.
    State slide = test::free_particles({{0.01f, sphere.radius + thickness, 0.0f}}, 0.01f);
    slide.motion.set(0, {0.02f, 0.0f, 0.0f});
    collide(slide, Collider::of(sphere), thickness);
    CHECK(slide.position.get(0).x == Approx(0.01f));
}

TEST_CASE("colliders implicit Euler, XPBD and projective at dt 0.1 with 1 substep drape the cloth on the sphere",
          "[colliders]") {
    for (const char* integrator : {"implicit-euler", "xpbd", "projective"}) {
        INFO(integrator);
        Scene scene = per_spring_scene("drape-sphere");  // the springs this was measured with
        apply_override(scene, std::string("integration.integrator=") + integrator);
        scene.settings.integration.dt = 0.1f;
        scene.settings.integration.substeps = 1;
        MassSpring sim = build_simulation(scene);
        sim.run_steps(30);  // 3 s
        REQUIRE(sim.all_finite());
        const SphereCollider& sphere = test::sphere(scene.settings.colliders);
        // The cloth lies on the sphere, not on the ground below it, and no particle is inside it.
        float highest = -1e9f;
        for (std::size_t i = 0; i < sim.particle_count(); ++i) highest = std::max(highest, sim.position(i).y);
        CHECK(highest > sphere.center.y + 0.9f * sphere.radius);
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            CHECK(signed_distance(sphere, sim.position(i)) > -1e-3f);
        }
    }
}

TEST_CASE("colliders a particle dropped on the cylinder's top face rests at top + thickness", "[colliders]") {
    const Collider support_disc = support(0.3f);
    const CylinderCollider& cylinder = std::get<CylinderCollider>(support_disc.shape);
    const double top = double(cylinder.center.y) + 0.5 * double(cylinder.height);
    const double thickness = 0.005;
    for (const char* integrator : {"verlet", "symplectic-euler", "rk4", "implicit-euler", "xpbd", "projective"}) {
        INFO(integrator);
        // Off the axis, dropped from 0.2 m above the top: it lands at 2 m/s after 0.2 s.
        Scene s = lone_particle({0.13f, 0.6f, -0.17f}, glm::vec3(0.0f), 20);
        test::collider(s.settings.colliders, "cylinder") = support_disc;
        apply_override(s, std::string("integration.integrator=") + integrator);
        MassSpring sim = build_simulation(s);
        double lowest = INFINITY;
        for (int step = 0; step < 60; ++step) {  // 1 s: falls, lands, rests
            sim.run_steps(1);
            lowest = std::min(lowest, double(signed_distance(cylinder, sim.position(0))));
        }
        const glm::dvec3 p = sim.state().position.get(0);
        INFO("rests at (" << p.x << ", " << p.y << ", " << p.z << "); top + thickness = " << top + thickness);
        CHECK(p.y == Approx(top + thickness).margin(1e-6));
        CHECK(p.x == Approx(0.13).margin(1e-6));  // straight down: no sideways push on the face
        CHECK(p.z == Approx(-0.17).margin(1e-6));
        // At rest: the contact removes each substep's fall (the motion). (Verlet's reported velocity adds
        // g h / 2 to it, its second-order estimate, so the motion is what says "at rest".)
        CHECK(glm::length(sim.state().motion.get(0)) < 1e-9);
        CHECK(lowest >= 0.0);  // never inside, landing included
    }
}

TEST_CASE("colliders the cylinder pushes particles out along the shortest way: faces, side, rims",
          "[colliders]") {
    // Radius 0.5, height 1 around the origin: the top face at y = 0.5, the side at r = 0.5.
    const CylinderCollider cylinder{{0.0f, 0.0f, 0.0f}, 0.5f, 1.0f};
    const float t = 0.01f;
    const glm::vec3 dir(std::cos(1.0f), 0.0f, -std::sin(1.0f));  // an arbitrary direction around the axis
    State st = test::free_particles({{0.1f, 0.45f, 0.2f},      // inside, nearest the top face
                                     {0.0f, -0.47f, 0.0f},     // inside, nearest the bottom face
                                     0.46f * dir,              // inside at mid height: leaves radially
                                     0.505f * dir,             // outside, in the side's shell
                                     0.3f * dir + glm::vec3(0.0f, 0.2f, 0.0f),  // pinned, inside
                                     {0.0f, 0.0f, 0.0f}},      // on the axis, at the centre: out of a face
                                    0.01f);
    st.pinned[4] = 1;
    collide(st, frictionless(cylinder), t);
    CHECK(st.position.get(0).y == Approx(0.51));
    CHECK(st.position.get(0).x == Approx(0.1f));
    CHECK(st.position.get(0).z == Approx(0.2f));
    CHECK(st.position.get(1).y == Approx(-0.51));
    const glm::dvec3 radial = st.position.get(2);
    CHECK(radial.y == 0.0);
    CHECK(glm::length(glm::dvec2(radial.x, radial.z)) == Approx(0.51));
    CHECK(glm::dot(glm::normalize(radial), glm::dvec3(dir)) == Approx(1.0));  // straight out from the axis
    CHECK(glm::length(st.position.get(3)) == Approx(0.51));
    CHECK(st.position.get(4) == glm::dvec3(0.3f * dir + glm::vec3(0.0f, 0.2f, 0.0f)));  // pinned: never moved
    CHECK(std::abs(st.position.get(5).y) == Approx(0.51));  // a face is nearer than the side (0.5 vs 0.5 + t)
    for (std::size_t i : {0u, 1u, 2u, 3u, 5u}) {
        INFO("particle " << i);
        CHECK(signed_distance(cylinder, st.position.get(i)) == Approx(t).margin(1e-6));
        CHECK(st.motion.get(i) == glm::dvec3(0.0));  // the push gives no velocity
    }

    // At a rim the nearest point of the solid is on the rim's circle. Inside, just below the top and just
    // inside the side, the particle leaves through the nearer of the two: straight up, or straight out.
    State rim = test::free_particles({{0.45f, 0.48f, 0.0f}, {0.48f, 0.45f, 0.0f}, {0.503f, 0.504f, 0.0f},
                                      0.503f * dir + glm::vec3(0.0f, -0.504f, 0.0f)},
                                     0.01f);
    collide(rim, frictionless(cylinder), t);
    CHECK(rim.position.get(0).y == Approx(0.51));  // 0.02 below the top, 0.05 inside the side: up
    CHECK(rim.position.get(0).x == Approx(0.45f));
    CHECK(rim.position.get(1).x == Approx(0.51));  // 0.05 below the top, 0.02 inside the side: out
    CHECK(rim.position.get(1).y == Approx(0.45f));
    // Outside, diagonally off the top rim (0.003 out, 0.004 up: 0.005 from the rim): pushed along that
    // diagonal to t from the rim, not straight up (the face's plane) nor straight out (the side's).
    CHECK(rim.position.get(2).x == Approx(0.5 + 0.6 * t));
    CHECK(rim.position.get(2).y == Approx(0.5 + 0.8 * t));
    CHECK(rim.position.get(2).z == 0.0);
    // The same off the bottom rim, around the axis.
    const glm::dvec3 bottom = rim.position.get(3);
    CHECK(glm::length(glm::dvec2(bottom.x, bottom.z)) == Approx(0.5 + 0.6 * t));
    CHECK(bottom.y == Approx(-0.5 - 0.8 * t));
    for (std::size_t i = 0; i < 4; ++i) {
        INFO("rim particle " << i);
        CHECK(signed_distance(cylinder, rim.position.get(i)) == Approx(t).margin(1e-6));
    }

    // Signed distances: inside (the nearer of face and side), beside the side, above a face, off a rim.
    CHECK(signed_distance(cylinder, {0.0f, 0.0f, 0.0f}) == Approx(-0.5f));
    CHECK(signed_distance(cylinder, {0.1f, 0.3f, 0.0f}) == Approx(-0.2f));
    CHECK(signed_distance(cylinder, {0.0f, 0.0f, 2.0f}) == Approx(1.5f));
    CHECK(signed_distance(cylinder, {0.3f, -1.5f, 0.0f}) == Approx(1.0f));
    CHECK(signed_distance(cylinder, {0.8f, 0.9f, 0.0f}) == Approx(0.5f));  // (0.3, 0.4) from the rim
}

TEST_CASE("colliders the cylinder removes inward motion and keeps the rest when frictionless", "[colliders]") {
    const CylinderCollider cylinder{{0.0f, 0.0f, 0.0f}, 0.5f, 1.0f};
    State st = test::free_particles({{0.1f, 0.505f, 0.0f}, {0.0f, 0.0f, 0.505f}}, 0.01f);
    st.motion.set(0, {0.02f, -0.01f, 0.0f});  // sliding over the top face and into it
    st.motion.set(1, {0.01f, 0.0f, -0.004f});  // sliding around the side and into it
    collide(st, frictionless(cylinder), 0.01f);
    CHECK(st.motion.get(0).x == Approx(0.02f));
    CHECK(st.motion.get(0).y == 0.0);
    CHECK(st.motion.get(1).x == Approx(0.01f));
    CHECK(st.motion.get(1).z == 0.0);
    st.position.set(0, {0.1f, 0.505f, 0.0f});
    st.motion.set(0, {0.0f, 0.03f, 0.0f});  // already leaving: keeps its outward motion
    collide(st, frictionless(cylinder), 0.01f);
    CHECK(st.motion.get(0).y == Approx(0.03f));
}

TEST_CASE("colliders a particle too fast for one substep does not pass through the cylinder", "[colliders]") {
    // Straight paths of 2 m in one substep through the middle of a cylinder of radius 0.3 around the origin:
    // across a tall one (height 1) through the side, down a flat one (height 0.4) through the top face. Each
    // is shaped so that 0.05 m past the centre the nearest way out is through the far side of the path.
    const CylinderCollider tall{{0.0f, 0.0f, 0.0f}, 0.3f, 1.0f};
    const CylinderCollider flat{{0.0f, 0.0f, 0.0f}, 0.3f, 0.4f};
    const float thickness = 0.01f;
    struct Path {
        const char* what;
        const CylinderCollider& cylinder;
        glm::vec3 axis;  // unit direction of travel
        float face;      // where the near surface is along it, from the centre
    };
    for (const Path& path : {Path{"through the side", tall, {1.0f, 0.0f, 0.0f}, 0.3f},
                             Path{"through the side, around the axis", tall, glm::normalize(glm::vec3(1.0f, 0.0f, -2.0f)), 0.3f},
                             Path{"down through the top face", flat, {0.0f, -1.0f, 0.0f}, 0.2f}}) {
        // Ends 1 m past the centre (outside), and 0.05 m past it (inside, nearest way out the far side).
        for (float end : {1.0f, 0.05f}) {
            INFO(path.what << ", ends " << end << " m past the centre");
            State st = test::free_particles({end * path.axis}, 0.01f);
            st.motion.set(0, (end + 1.0f) * path.axis);  // came from 1 m before the centre
            collide(st, frictionless(path.cylinder), thickness);
            const glm::dvec3 p = st.position.get(0);
            CHECK(glm::dot(p, glm::dvec3(path.axis)) == Approx(-(path.face + thickness)).margin(1e-5));  // near side
            CHECK(glm::length(p - glm::dot(p, glm::dvec3(path.axis)) * glm::dvec3(path.axis)) < 1e-6);  // on its path
            CHECK(glm::length(st.motion.get(0)) == Approx(0.0).margin(1e-6));  // its (all inward) motion gone
        }
    }
    const CylinderCollider& cylinder = flat;
    // Across a rim: from above and beside the top rim, down and across to below the far side. It enters the
    // shell through the top face's plane, beyond the side's: it stops there, its downward motion removed.
    {
        State st = test::free_particles({{-0.5f, -0.5f, 0.0f}}, 0.01f);
        const glm::dvec3 start(0.35, 0.4, 0.0);
        st.motion.set(0, st.position.get(0) - start);
        collide(st, frictionless(cylinder), thickness);
        const glm::dvec3 p = st.position.get(0);
        CHECK(signed_distance(cylinder, p) > 0.0f);
        CHECK(p.y == Approx(0.2 + thickness).margin(1e-5));  // where the path met the top face's shell
        CHECK(st.motion.get(0).y == Approx(0.0).margin(1e-9));
        CHECK(st.motion.get(0).x < 0.0);  // the sideways part kept
    }
    // Starting beside the top rim, in the corner where the rounded shell leaves room (outside the shell but
    // within thickness of both the face's and the side's planes), heading through the solid: stopped where it
    // started, its motion toward the rim removed.
    {
        const glm::dvec3 start(0.3 + 0.9 * thickness, 0.2 + 0.9 * thickness, 0.0);
        REQUIRE(signed_distance(cylinder, glm::vec3(start)) > thickness);
        State st = test::free_particles({{-1.0f, 0.0f, 0.0f}}, 0.01f);
        st.motion.set(0, st.position.get(0) - start);
        collide(st, frictionless(cylinder), thickness);
        CHECK(glm::length(st.position.get(0) - start) < 1e-6);
        // From the rim's circle (the float radius and half height) to the start: about (1, 1) / sqrt(2).
        const glm::dvec3 rim_normal =
            glm::normalize(start - glm::dvec3(double(cylinder.radius), 0.5 * double(cylinder.height), 0.0));
        CHECK(glm::dot(st.motion.get(0), rim_normal) == Approx(0.0).margin(1e-9));
    }
    // A glancing path that stays in the thickness shell (a particle sliding over the top face) is not a pass.
    State slide = test::free_particles({{0.01f, 0.2f + thickness, 0.0f}}, 0.01f);
    slide.motion.set(0, {0.02f, 0.0f, 0.0f});
    collide(slide, frictionless(cylinder), thickness);
    CHECK(slide.position.get(0).x == Approx(0.01f));
    CHECK(slide.motion.get(0).x == Approx(0.02f));
}

TEST_CASE("colliders friction on the cylinder's top face slows sliding at mu g and stops it at v^2 / (2 mu g)",
          "[colliders]") {
    // A wide disc (radius 0.5) so the particle stops on it: at most 0.255 m from x = -0.4 at 1 m/s.
    const float v0 = 1.0f;
    auto sliding = [&](float mu) {
        const Collider cylinder{CylinderCollider{{0.0f, 0.1f, 0.0f}, 0.5f, 0.2f}, mu, true, {}};
        Scene s = lone_particle({-0.4f, 0.2f + 0.005f, 0.0f}, {v0, 0.0f, 0.0f}, 20);
        test::collider(s.settings.colliders, "cylinder") = cylinder;
        return build_simulation(s);
    };
    {
        MassSpring sim = sliding(0.0f);
        sim.run_steps(30);  // 0.5 s
        CHECK(sim.position(0).x == Approx(-0.4f + 0.5f * v0).epsilon(1e-4));
        CHECK(sim.velocities()[0].x == Approx(v0).epsilon(1e-4));
        CHECK(sim.position(0).y == Approx(0.205f).margin(1e-6));
    }
    for (float mu : {0.2f, 0.5f, 1.0f}) {
        MassSpring sim = sliding(mu);
        const double stop_time = v0 / (mu * 9.81);
        sim.run_steps(static_cast<long long>(std::ceil(0.5 * stop_time * 60)));
        CHECK(sim.velocities()[0].x == Approx(v0 - mu * 9.81 * sim.time()).epsilon(0.02));
        sim.run_steps(static_cast<long long>(std::ceil(stop_time * 60)));
        const double distance = v0 * v0 / (2.0 * mu * 9.81);
        INFO("mu " << mu << ": stopped after " << sim.position(0).x + 0.4 << " m, expected " << distance);
        CHECK(sim.position(0).x + 0.4 == Approx(distance).epsilon(0.005));
        CHECK(std::fabs(sim.velocities()[0].x) < 1e-3);
        CHECK(sim.position(0).y == Approx(0.205f).margin(1e-6));  // still on the face
    }
}

TEST_CASE("colliders a cloth drapes over the cylinder: none inside, on the top face and down the side",
          "[colliders]") {
    // Under the sanitizers Verlet alone (implicit Euler's contact with the cylinder takes 90 s there; its
    // solver meets the colliders under them in "implicit Euler, XPBD and projective at dt 0.1 ...").
    for (const char* integrator : test::kSanitized ? std::vector<const char*>{"verlet"}
                                                  : std::vector<const char*>{"verlet", "implicit-euler"}) {
        INFO(integrator);
        Scene scene = drape_on_cylinder();
        apply_override(scene, std::string("integration.integrator=") + integrator);
        MassSpring sim = build_simulation(scene);
        const CylinderCollider& c = test::cylinder(scene.settings.colliders);
        const float top = c.center.y + 0.5f * c.height, thickness = scene.settings.colliders.thickness;
        float worst = INFINITY;
        for (int step = 0; step < 180; ++step) {  // 3 s: falls, hits, drapes, settles
            sim.run_steps(1);
            for (std::size_t i = 0; i < sim.particle_count(); ++i) {
                worst = std::min(worst, signed_distance(c, sim.position(i)));
            }
        }
        REQUIRE(sim.all_finite());
        int on_top = 0, on_side = 0;
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            const glm::vec3 p = sim.position(i) - c.center;
            const float r = std::sqrt(p.x * p.x + p.z * p.z);
            if (r < c.radius - 0.01f && std::abs(p.y + c.center.y - (top + thickness)) < 1e-4f) ++on_top;
            if (std::abs(r - (c.radius + thickness)) < 2e-3f && p.y < 0.5f * c.height - 0.05f) ++on_side;
        }
        INFO("smallest clearance " << worst << " m; " << on_top << " particles on the top face, " << on_side
                                   << " against the side");
        CHECK(worst >= 0.0f);
        CHECK(on_top > 100);  // the disc of radius 0.3 under a 1.2 m, 40 x 40 cloth holds about 200
        CHECK(on_side > 0);
    }
}

TEST_CASE("colliders a cloth dropped on two spheres, two boxes and a cylinder stays outside every one, every step, on every path", "[colliders]") {
    const Scene loaded = load_scene_file(std::string(CLOTHSIM_TEST_DATA) + "/scene_shapes.toml");
    const std::vector<Collider>& shapes = loaded.settings.colliders.shapes;
    REQUIRE(shapes.size() == 6);  // as listed: sphere, sphere, box, box, cylinder, plane
    std::array<int, kColliderKindCount> count{};
    for (const Collider& c : shapes) ++count[c.kind()];
    CHECK(count == std::array<int, kColliderKindCount>{2, 2, 1, 1});
    for (const char* method : {"fast", "textbook"}) {
        Scene scene = loaded;
        apply_override(scene, std::string("solver.method=") + method);
        MassSpring sim = build_simulation(scene);
        const float thickness = scene.settings.colliders.thickness;
        int touching = 0;  // particles within the thickness shell of a shape at the end: the cloth lies on them
        for (int step = 0; step < 120; ++step) {
            sim.run_steps(1);
            for (std::size_t i = 0; i < sim.particle_count(); ++i) {
                for (const Collider& c : shapes) {
                    INFO(method << ", step " << step << ", particle " << i << ", " << kind_name(c));
                    REQUIRE(signed_distance(c, sim.position(i)) > thickness - 1e-4f);
                    if (step == 119 && signed_distance(c, sim.position(i)) < 2.0f * thickness) ++touching;
                }
            }
        }
        CHECK(touching > 100);  // it came to rest on the shapes, not beside them
    }
}

namespace {

// A mesh collider of `mesh`, placed, frictionless.
Collider mesh_collider(TriangleMesh mesh, glm::vec3 position, glm::vec3 rotation = glm::vec3(0.0f), float scale = 1.0f) {
    MeshCollider m;
    m.mesh = std::make_shared<const TriangleMesh>(std::move(mesh));
    m.position = position;
    m.rotation = rotation;
    m.scale = scale;
    return frictionless(m);
}

// hanging's per-spring cloth as a level square of n x n particles, `side` metres across, centred over the
// origin at height y.
Scene level_square(int n, float side, float y) {
    Scene scene = per_spring_scene("hanging");
    scene.cloth.rows = scene.cloth.cols = n;
    scene.cloth.origin = {-0.5f * side, y, -0.5f * side};
    scene.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    scene.cloth.v_axis = {0.0f, 0.0f, 1.0f};
    scene.cloth.size = {side, side};
    return scene;
}

}  // namespace

TEST_CASE("colliders a mesh pushes a particle as the analytic shape it meshes: an icosphere as the sphere, a turned "
          "and scaled box as the box", "[colliders]") {
    const float thickness = 0.01f;
    // 20480 triangles: the chord sags 6e-5 m below the sphere of radius 0.3, the normals turn by 2 degrees.
    const Collider ball = mesh_collider(icosphere(0.3, 5), {0.1f, 0.5f, -0.2f});
    const Collider sphere = frictionless(SphereCollider{{0.1f, 0.5f, -0.2f}, 0.3f});
    // A 1 x 0.2 x 0.5 box at half size, doubled and turned 90 degrees about y: the box 1 x 0.4 x 2.
    const Collider slab = mesh_collider(box_mesh({0.25, 0.2, 0.5}), {0.0f, 0.3f, 0.0f}, {0.0f, 90.0f, 0.0f}, 2.0f);
    const Collider box = frictionless(BoxCollider{{0.0f, 0.3f, 0.0f}, {1.0f, 0.4f, 0.5f}});
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), shell(-0.02, 0.012);
    int touching = 0;
    for (int k = 0; k < 3000; ++k) {
        // A point at depth `shell` below the sphere's shell surface, in a random direction.
        glm::dvec3 dir(unit(rng), unit(rng), unit(rng));
        if (glm::length(dir) < 1e-3) continue;
        dir = glm::normalize(dir);
        const glm::dvec3 p = glm::dvec3(0.1, 0.5, -0.2) + (0.3 + shell(rng)) * dir;
        const Contact<double> analytic = contact(std::get<SphereCollider>(sphere.shape), p, double(thickness));
        const Contact<double> meshed = contact(std::get<MeshCollider>(ball.shape), p, double(thickness));
        INFO("point " << k << " at depth " << analytic.depth);
        // Both see the contact in the shell where it is clear (away from its edges by more than the sag); deeper
        // inside, the mesh sees nothing (continuous collision keeps particles from getting there: mesh.hpp).
        if (analytic.depth > 2e-4 && analytic.depth < thickness - 2e-4) {
            ++touching;
            REQUIRE(meshed.depth > 0.0);
            CHECK(std::fabs(meshed.depth - analytic.depth) < 1.5e-4);
            CHECK(glm::dot(meshed.normal, analytic.normal) > 0.998);
        } else if (analytic.depth < -2e-4) {
            CHECK(!(meshed.depth > 0.0));
        }
        // The box: exact (flat faces), at points around it.
        const glm::dvec3 q(0.6 * unit(rng), 0.3 + 0.25 * unit(rng), 0.3 * unit(rng));
        const Contact<double> flat = contact(std::get<BoxCollider>(box.shape), q, double(thickness));
        const Contact<double> turned = contact(std::get<MeshCollider>(slab.shape), q, double(thickness));
        if (flat.depth > 0.0 && flat.depth <= thickness) {  // the mesh sees the thickness shell only
            REQUIRE(turned.depth > 0.0);
            CHECK(turned.depth == Approx(flat.depth).margin(1e-9));
            CHECK(glm::dot(turned.normal, flat.normal) == Approx(1.0).margin(1e-9));
        }
        CHECK(signed_distance(std::get<MeshCollider>(slab.shape), glm::vec3(q)) ==
              Approx(signed_distance(std::get<BoxCollider>(box.shape), glm::vec3(q))).margin(1e-6));
    }
    CHECK(touching > 500);
    // The bounds and the broad phase's test hold the turned box.
    const Box b = bounds(slab);
    CHECK(b.lo.x == Approx(-0.5f));
    CHECK(b.hi.z == Approx(0.25f));
    CHECK(b.hi.y == Approx(0.5f));
    CHECK(may_touch(slab, thickness, Box{{0.49f, 0.3f, 0.0f}, {0.6f, 0.31f, 0.1f}}));
    CHECK_FALSE(may_touch(slab, thickness, Box{{0.52f, 0.3f, 0.0f}, {0.6f, 0.31f, 0.1f}}));
}

TEST_CASE("colliders a cloth falling at 5 m/s with one substep per 1/60 s never passes a 2 mm thin mesh slab",
          "[colliders]") {
    // 83 mm a substep against a slab 2 mm thick, level and tilted 30 degrees; without the sweep the whole
    // cloth falls through in one substep. Every particle stays above the slab's upper face, every step.
    for (float tilt : {0.0f, 30.0f}) {
        INFO("tilt " << tilt);
        Scene scene = level_square(12, 0.6f, 0.8f);
        scene.pins = PinSpec{};
        scene.settings.integration.substeps = 1;  // XPBD: stable at any substep (Verlet is not, at 1/60 s)
        scene.settings.integration.integrator = Integrator::Xpbd;
        scene.settings.colliders.shapes = {mesh_collider(box_mesh({1.5, 0.002, 1.5}), {0.0f, 0.5f, 0.0f}, {tilt, 0.0f, 0.0f})};
        MassSpring sim = build_simulation(scene);
        for (std::size_t i = 0; i < sim.particle_count(); ++i) sim.set_particle(i, sim.position(i), {0.0f, -5.0f, 0.0f});
        const MeshCollider& slab = std::get<MeshCollider>(scene.settings.colliders.shapes[0].shape);
        for (int step = 0; step < 60; ++step) {
            sim.run_steps(1);
            for (std::size_t i = 0; i < sim.particle_count(); ++i) {
                INFO("step " << step << ", particle " << i);
                // Above the slab's upper face (distance from the slab, on its +y side of the tilted plane).
                const glm::dvec3 local = placed(slab).to_mesh(glm::dvec3(sim.position(i)));
                REQUIRE(local.y > 0.001 - 1e-5);
            }
        }
    }
}

TEST_CASE("colliders the tablecloth settles on the round table mesh: no particle inside it or nearer than half the "
          "thickness", "[colliders]") {
    Scene scene = load_scene("tablecloth");
    scene.cloth.rows = scene.cloth.cols = 24;  // the drape at a 6 cm spacing: 3 s in a few seconds of testing
    MassSpring sim = build_simulation(scene);
    sim.run_steps(180);
    REQUIRE(sim.all_finite());
    const MeshCollider& table = std::get<MeshCollider>(scene.settings.colliders.shapes[0].shape);
    REQUIRE(table.mesh->closed());
    const float thickness = scene.settings.colliders.thickness;
    int on_top = 0;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        INFO("particle " << i);
        const glm::dvec3 local = placed(table).to_mesh(glm::dvec3(sim.position(i)));
        CHECK(table.mesh->winding_number(local) < 0.5);  // outside the solid
        CHECK(signed_distance(table, sim.position(i)) > 0.5f * thickness);
        on_top += local.y > 0.76 && glm::length(glm::dvec2(local.x, local.z)) < 0.45;
    }
    CHECK(on_top > 100);  // it lies on the table, not on the floor beside it
}

namespace {

// How many particles lie inside the closed mesh `collider` (winding number), how many of those deeper than
// `thickness`, and the smallest signed distance to it of those outside.
struct MeshClearance {
    int inside = 0, deep = 0;
    float nearest = INFINITY;
};
MeshClearance mesh_clearance(const MassSpring& sim, const Collider& collider, float thickness) {
    const MeshCollider& m = std::get<MeshCollider>(collider.shape);
    const PlacedMesh at = placed(m);
    MeshClearance c;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const float distance = signed_distance(m, sim.position(i));
        if (m.mesh->winding_number(at.to_mesh(glm::dvec3(sim.position(i)))) > 0.5) {
            ++c.inside;
            c.deep += distance < -thickness * (1.0f + 1e-4f);
        } else {
            c.nearest = std::min(c.nearest, distance);
        }
    }
    return c;
}

}  // namespace

TEST_CASE("colliders a mesh that jumps onto the cloth (a typed position, a dropped mesh) pushes out every particle "
          "it swallowed", "[colliders]") {
    // The tablecloth settled on its table (at a 6 cm spacing), then the table typed 3 cm higher: its top, 6 cm
    // thick, swallows the cloth lying on it 2.2 cm deep, beyond the 8 mm shell the mesh's contact sees. At once
    // no particle is deeper inside than the shell (those in it are the contact's), and a step later none is
    // inside or nearer than half the thickness.
    Scene scene = load_scene("tablecloth");
    scene.cloth.rows = scene.cloth.cols = 24;
    MassSpring sim = build_simulation(scene);
    sim.run_steps(60);
    const float thickness = scene.settings.colliders.thickness;
    SimulationSettings raised = sim.settings();
    std::get<MeshCollider>(raised.colliders.shapes[0].shape).position.y += 0.03f;
    CHECK(mesh_clearance(sim, raised.colliders.shapes[0], thickness).deep > 100);  // what the jump swallows
    sim.apply(raised);
    CHECK(mesh_clearance(sim, sim.colliders()[0], thickness).deep == 0);
    sim.run_steps(1);
    const MeshClearance stepped = mesh_clearance(sim, sim.colliders()[0], thickness);
    CHECK(stepped.inside == 0);
    CHECK(stepped.nearest > 0.5f * thickness);
    sim.run_steps(30);
    REQUIRE(sim.all_finite());
    const MeshClearance settled = mesh_clearance(sim, sim.colliders()[0], thickness);
    CHECK(settled.inside == 0);
    CHECK(settled.nearest > 0.5f * thickness);

    // A box mesh dropped onto the cloth: a new collider, 20 cm across, half sunk into the table top.
    SimulationSettings dropped = sim.settings();
    MeshCollider box;
    box.mesh = std::make_shared<const TriangleMesh>(box_mesh({0.2, 0.2, 0.2}));
    box.position = {0.1f, 0.79f, -0.05f};
    dropped.colliders.shapes.push_back(frictionless(box));
    CHECK(mesh_clearance(sim, dropped.colliders.shapes.back(), thickness).deep > 10);
    sim.apply(dropped);
    CHECK(mesh_clearance(sim, sim.colliders().back(), thickness).deep == 0);
    sim.run_steps(10);
    REQUIRE(sim.all_finite());
    for (const Collider& c : sim.colliders()) {
        if (!std::holds_alternative<MeshCollider>(c.shape)) continue;
        const MeshClearance around = mesh_clearance(sim, c, thickness);
        CHECK(around.inside == 0);
        CHECK(around.nearest > 0.5f * thickness);
    }
}

TEST_CASE("colliders a cloth built inside a closed mesh starts outside it, an open mesh moves nothing", "[colliders]") {
    Scene scene = level_square(10, 0.4f, 0.5f);
    scene.pins = PinSpec{PinPreset::None, {}, 0.0f, ClipKind::Rigid};
    MeshCollider box;
    box.mesh = std::make_shared<const TriangleMesh>(box_mesh({0.8, 0.6, 0.8}));  // y from 0 to 0.6
    box.position = {0.0f, 0.3f, 0.0f};
    scene.settings.colliders.shapes = {frictionless(box)};
    const MassSpring sim = build_simulation(scene);
    const MeshClearance c = mesh_clearance(sim, sim.colliders()[0], scene.settings.colliders.thickness);
    CHECK(c.inside == 0);
    CHECK(c.nearest > 0.5f * scene.settings.colliders.thickness);
    // Out through the top: the cloth lies 10 cm under it and 20 cm or more from every side.
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        CHECK(sim.position(i).y == Approx(0.6f + scene.settings.colliders.thickness).margin(1e-5));
    }

    // A sheet has no inside: nothing moves.
    MeshCollider sheet;
    sheet.mesh = std::make_shared<const TriangleMesh>(TriangleMesh({{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}}, {{0, 2, 1}, {0, 3, 2}}));
    State state = sim.state();
    const State kept = state;
    CHECK(push_out_of_mesh(state, frictionless(sheet), 0.005f) == 0);
    CHECK(state.position.y == kept.position.y);
}

TEST_CASE("colliders the sphere's four-lane block test moves every particle as the particle-by-particle test, on "
          "every kernel", "[colliders]") {
    ColliderSettings colliders;
    const glm::dvec3 centre(glm::vec3(0.1f, 0.5f, -0.2f));  // as the collider holds it: r = 0 is its centre
    colliders.shapes = {Collider{SphereCollider{glm::vec3(centre), 0.35f}, 0.4f, true, {}}};
    colliders.thickness = 0.005f;
    // Particles from the centre to outside the shell and its thickness, moving slowly (a push with friction)
    // or fast (a path through the sphere: the swept test), a few exactly at the centre, one NaN, and one
    // block holding a pinned particle.
    const std::size_t n = 64 * kBlockParticles;
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), radius(0.0, 0.37), slow(-0.002, 0.002), fast(-0.4, 0.4);
    State start = test::free_state(n);
    for (std::size_t i = 0; i < n; ++i) {
        glm::dvec3 direction(unit(rng), unit(rng), unit(rng));
        if (glm::length(direction) < 1e-3) direction = {0.0, 1.0, 0.0};
        const double r = i % 53 == 0 ? 0.0 : i % 3 == 0 ? 0.35 + 0.005 * unit(rng) : radius(rng);
        start.position.set(i, centre + r * glm::normalize(direction));
        const bool swept = i % 7 == 0;
        start.motion.set(i, swept ? glm::dvec3(fast(rng), fast(rng), fast(rng)) : glm::dvec3(slow(rng), slow(rng), slow(rng)));
    }
    start.position.x[100] = std::nan("");
    start.pinned[5 * kBlockParticles + 3] = 1;
    test::with_every_kernel([&] {
        State blocked = start, one_by_one = start;
        CollisionBlocks blocks;
        blocks.start = block_starts(n, 0, 0);
        collide_stage(blocked, colliders, false, blocks, nullptr, 1);
        collide_all(one_by_one, colliders);
        CHECK(same_bits(blocked.position, one_by_one.position));
        CHECK(same_bits(blocked.motion, one_by_one.motion));
        std::size_t pushed = 0;
        for (std::size_t i = 0; i < n; ++i) pushed += blocked.position.y[i] != start.position.y[i] ? 1 : 0;
        CHECK(pushed > n / 2);
    });
}

TEST_CASE("colliders the bundled mesh drapes hold: settled for 3 s, no particle is inside a mesh and none closer "
          "than half the thickness",
          "[settled]") {
    // tablecloth (the round table), mannequin-drape, chair-drape and tabard at their own size: the generalised winding
    // number (TriangleMesh::winding_number) says inside, the tree the distance.
    for (const char* name : {"tablecloth", "mannequin-drape", "chair-drape", "tabard"}) {
        INFO("scene " << name);
        const Scene scene = load_scene(name);
        MassSpring sim = build_simulation(scene);
        sim.run_steps(180);
        REQUIRE(sim.all_finite());
        const float thickness = scene.settings.colliders.thickness;
        for (const Collider& c : sim.colliders()) {
            const auto* m = std::get_if<MeshCollider>(&c.shape);
            if (!m) continue;
            REQUIRE(m->mesh);
            const PlacedMesh at = placed(*m);
            int inside = 0, close = 0;
            for (std::size_t i = 0; i < sim.particle_count(); ++i) {
                const glm::dvec3 q = at.to_mesh(glm::dvec3(sim.position(i)));
                inside += m->mesh->winding_number(q) > 0.5;
                const auto near = m->mesh->nearest(q, 0.5 * thickness / at.scale);
                close += near && glm::length(near->point - q) * at.scale < 0.5 * thickness;
            }
            CHECK(inside == 0);
            CHECK(close == 0);
        }
    }
}

TEST_CASE("colliders a mesh dragged hard under a cloth (move_collider, as the app's alt+drag) leaves no particle "
          "inside it",
          "[settled]") {
    // tablecloth settled for 1 s, then its table pulled 0.6 m sideways in 0.3 s (2 m/s, frame by frame) and
    // lifted 0.1 m: the cloth is pushed and carried, and no particle ends inside the table (winding number).
    // At the scene's 104 substeps the table moves 0.3 mm a substep, inside the 8 mm shell, so the proximity
    // test holds it on its own; a move farther than the shell in one substep is the relative sweep's, tested
    // in test_collider_motion.cpp (a 2 mm slab at 10 m/s).
    const Scene scene = load_scene("tablecloth");
    MassSpring sim = build_simulation(scene);
    sim.run_steps(60);
    const double dt = scene.settings.integration.dt;
    for (int frame = 1; frame <= 18; ++frame) {
        const glm::vec3 to(0.6f * frame / 18.0f, 0.1f * frame / 18.0f, 0.0f);
        REQUIRE(sim.move_collider(0, to, dt));
        sim.run_steps(1);
        const auto& m = std::get<MeshCollider>(sim.colliders()[0].shape);
        const PlacedMesh at = placed(m);
        int inside = 0;
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            inside += m.mesh->winding_number(at.to_mesh(glm::dvec3(sim.position(i)))) > 0.5;
        }
        INFO("frame " << frame);
        CHECK(inside == 0);
    }
    REQUIRE(sim.all_finite());
}

TEST_CASE("colliders the cloth's box from the fast solver's bands culls no contact: bit for bit without the broad "
          "phase",
          "[colliders]") {
    // A cloth hanging its first rows onto the ground, on 1, 2 and 3 threads.
    // hanging held by its last row's corners, so rows 0.. (the first band) hang lowest, with the ground raised
    // to meet them: the tethers' job boxes the blocks band by band, each band's union of boxes kept for the
    // collision stage's cloth box (CollisionBlocks::band_union).
    Scene scene = load_scene("hanging");
    apply_override(scene, "pins=[[31, 0], [31, 31]]");
    scene.settings.colliders.shapes.at(0).shape = PlaneCollider{0.75f};
    for (const int threads : {1, 2, 3}) {
        INFO(threads << " threads");
        Scene culled = scene, every = scene;
        apply_override(culled, "solver.threads=" + std::to_string(threads));
        apply_override(every, "solver.threads=" + std::to_string(threads));
        apply_override(every, "solver.broad_phase=false");
        MassSpring a = build_simulation(culled), b = build_simulation(every);
        a.run_steps(90);
        b.run_steps(90);
        REQUIRE(a.last_step_fast());
        CHECK(same_bits(a.state().position, b.state().position));
        double lowest = 1e9;
        for (std::size_t i = 0; i < a.particle_count(); ++i) lowest = std::min(lowest, double(a.position(i).y));
        CHECK(lowest < 0.75 + scene.settings.colliders.thickness + 1e-3);  // the ground holds it up
        CHECK(lowest > 0.75);
    }
}
