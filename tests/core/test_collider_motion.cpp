// Kinematic colliders (include/clothsim/collider_motion.hpp): a collider that moves and turns on a script, met
// with the motion relative to its surface.
#include "support.hpp"

#include "clothsim/collider_motion.hpp"
#include "clothsim/mesh_shapes.hpp"
#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

using namespace clothsim;

namespace {

// A flat n x n cloth of side `size` lying at height y, per-spring form, undamped, no pins and no colliders.
Scene flat_cloth(int n, float size, float y) {
    Scene s;
    s.cloth.rows = s.cloth.cols = n;
    s.cloth.size = {size, size};
    s.cloth.origin = {-0.5f * size, y, -0.5f * size};
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.0f, 0.0f, 1.0f};
    s.pins.preset = PinPreset::None;
    s.settings.springs.damping = 0.0f;
    s.settings.colliders.shapes.clear();
    s.settings.solver.sleep_speed = 0.0f;
    return s;
}

double lowest_y(const MassSpring& sim) {
    double y = INFINITY;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) y = std::min(y, double(sim.position(i).y));
    return y;
}

}  // namespace

TEST_CASE("collider motion: a translation moves the surface by v h everywhere, a spin by the turn's chord") {
    Collider ball = Collider::of(SphereCollider{{1.0f, 2.0f, 3.0f}, 0.5f});
    ball.motion.velocity = {2.0f, 0.0f, -1.0f};
    const double t0 = 0.25, h = 0.01;
    const SurfaceMotion slide = surface_motion(ball, t0, t0 + h);
    for (const glm::dvec3 p : {glm::dvec3(1.5, 2.0, 3.0), glm::dvec3(-4.0, 7.0, 0.5)}) {
        const glm::dvec3 d = slide.displacement(p);
        CHECK(d.x == Approx(0.02).margin(1e-12));
        CHECK(d.y == Approx(0.0).margin(1e-12));
        CHECK(d.z == Approx(-0.01).margin(1e-12));
    }
    CHECK(slide.reach >= glm::length(glm::dvec3(0.02, 0.0, -0.01)));
    Collider pose = ball;
    pose_at(ball, 1.5, pose);
    CHECK(std::get<SphereCollider>(pose.shape).center.x == Approx(4.0f));
    CHECK(std::get<SphereCollider>(pose.shape).center.z == Approx(1.5f));

    // Spinning at w about z (counter-clockwise seen from +z): the point at +x of the centre moves toward +y,
    // by r (1 - cos wh) back and r sin wh up.
    Collider spun = Collider::of(SphereCollider{{1.0f, 2.0f, 3.0f}, 0.5f});
    spun.motion.spin = {0.0f, 0.0f, 90.0f};
    const double angle = 90.0 * h * std::numbers::pi / 180.0;
    const SurfaceMotion turn = surface_motion(spun, t0, t0 + h);
    const glm::dvec3 d = turn.displacement(glm::dvec3(1.5, 2.0, 3.0));
    CHECK(d.x == Approx(0.5 * (1.0 - std::cos(angle))).margin(1e-12));
    CHECK(d.y == Approx(0.5 * std::sin(angle)).margin(1e-12));
    CHECK(d.z == Approx(0.0).margin(1e-12));
    CHECK(turn.reach >= glm::length(d));
}

TEST_CASE("collider motion: a cloth on a moving floor is carried by friction, at mu g up to the floor's speed") {
    // Coulomb friction on a floor moving at V: the cloth's speed grows at mu g until it reaches V, then stays.
    const float mu = 0.4f, speed = 1.0f, g = 9.81f;
    Scene s = flat_cloth(6, 0.2f, 0.005f);  // resting on the floor's thickness shell
    Collider floor = Collider::of(PlaneCollider{});
    floor.friction = mu;
    floor.motion.velocity = {speed, 0.0f, 0.0f};
    s.settings.colliders.shapes = {floor};
    s.settings.integration.substeps = 8;
    MassSpring sim = build_simulation(s);
    auto mean_vx = [&] {
        double sum = 0.0;
        for (const glm::vec3& v : sim.velocities()) sum += v.x;
        return sum / static_cast<double>(sim.particle_count());
    };
    const double reached = speed / (mu * g);  // s: when the cloth reaches the floor's speed
    while (sim.time() < 0.5 * reached) sim.run_steps(1);
    CHECK(mean_vx() == Approx(mu * g * sim.time()).epsilon(0.05));
    while (sim.time() < 2.0 * reached) sim.run_steps(1);
    CHECK(mean_vx() == Approx(speed).epsilon(0.01));
    // The floor stays at its height: it moves along itself, a conveyor belt.
    CHECK(lowest_y(sim) == Approx(0.005).margin(1e-3));
}

TEST_CASE("collider motion: a 2 mm slab at 10 m/s carries a cloth with it, none left behind (relative sweep)") {
    // 1/60 s substeps: the slab moves 17 cm a substep, 80 times its own thickness. The contact at the
    // substep's end alone would find the cloth far below it; the sweep of the relative path stops every
    // particle at the slab's face. For the analytic box and for a mesh of it.
    const float thickness = 0.002f;
    for (const bool mesh : {false, true}) {
        INFO((mesh ? "mesh slab" : "box slab"));
        Scene s = flat_cloth(8, 0.4f, 0.5f);
        s.settings.forces.gravity = glm::vec3(0.0f);
        s.settings.integration.dt = 1.0f / 60.0f;
        s.settings.integration.substeps = 1;
        Collider slab;
        if (mesh) {
            MeshCollider m;
            m.mesh = std::make_shared<const TriangleMesh>(box_mesh(glm::dvec3(1.0, thickness, 1.0)));
            m.position = {0.0f, 0.45f, 0.0f};
            slab = Collider::of(m);
        } else {
            slab = Collider::of(BoxCollider{{0.0f, 0.45f, 0.0f}, {1.0f, thickness, 1.0f}});
        }
        slab.motion.velocity = {0.0f, 10.0f, 0.0f};
        s.settings.colliders.shapes = {slab};
        MassSpring sim = build_simulation(s);
        for (int i = 0; i < 12; ++i) sim.run_steps(1);
        const double top = 0.45 + 10.0 * sim.time() + 0.5 * thickness;
        // Every particle on the slab's upper face, at the collision thickness, none below it.
        CHECK(lowest_y(sim) >= top + 0.5 * s.settings.colliders.thickness);
        CHECK(lowest_y(sim) <= top + 1.01 * s.settings.colliders.thickness);
        float slowest = INFINITY, fastest = -INFINITY;
        for (const glm::vec3& v : sim.velocities()) slowest = std::min(slowest, v.y), fastest = std::max(fastest, v.y);
        CHECK(slowest == Approx(10.0f).epsilon(1e-3));
        CHECK(fastest == Approx(10.0f).epsilon(1e-3));
        // What the renderer draws and the export writes: the slab where it is now.
        const Collider& now = sim.colliders()[0];
        const float y = mesh ? std::get<MeshCollider>(now.shape).position.y : std::get<BoxCollider>(now.shape).center.y;
        CHECK(y == Approx(top - 0.5 * thickness).epsilon(1e-5));
    }
}

TEST_CASE("collider motion: a spinning ball drags a cloth resting on it the way its surface turns") {
    // A small patch on top of a ball spinning about z at w: the top of the ball moves at -w r along x, and the
    // patch, held by friction, follows that way.
    Scene s = flat_cloth(3, 0.02f, 0.305f);
    Collider ball = Collider::of(SphereCollider{{0.0f, 0.0f, 0.0f}, 0.3f});
    ball.friction = 1.0f;
    ball.motion.spin = {0.0f, 0.0f, 30.0f};
    s.settings.colliders.shapes = {ball};
    MassSpring sim = build_simulation(s);
    for (int i = 0; i < 6; ++i) sim.run_steps(1);
    double vx = 0.0;
    for (const glm::vec3& v : sim.velocities()) vx += v.x / static_cast<double>(sim.particle_count());
    const double surface_speed = 30.0 * std::numbers::pi / 180.0 * 0.3;  // m/s
    CHECK(vx < -0.5 * std::min(surface_speed, 1.0 * 9.81 * sim.time()));
    CHECK(vx > -1.05 * surface_speed);
    // Without the spin, the patch on the top stays put.
    s.settings.colliders.shapes[0].motion.spin = glm::vec3(0.0f);
    MassSpring still = build_simulation(s);
    for (int i = 0; i < 6; ++i) still.run_steps(1);
    for (const glm::vec3& v : still.velocities()) CHECK(std::abs(v.x) < 1e-3f);
}

TEST_CASE("collider motion: a moving collider keeps the cloth awake, a still one lets it sleep") {
    Scene s = flat_cloth(4, 0.2f, 0.005f);
    s.settings.solver.sleep_speed = 0.01f;
    s.settings.solver.sleep_time = 0.2f;
    Collider far = Collider::of(SphereCollider{{5.0f, 0.5f, 5.0f}, 0.2f});
    s.settings.colliders.shapes = {Collider::of(PlaneCollider{}), far};
    MassSpring still = build_simulation(s);
    while (still.time() < 1.0) still.run_steps(1);
    CHECK(still.asleep());
    s.settings.colliders.shapes[1].motion.velocity = {-1.0f, 0.0f, -1.0f};  // on its way to the cloth
    MassSpring moving = build_simulation(s);
    while (moving.time() < 1.0) moving.run_steps(1);
    CHECK_FALSE(moving.asleep());
}

TEST_CASE("collider motion: a dragged box (move_collider) carries the cloth lying on it by friction, and stays "
          "where the drag left it") {
    // A board 1 cm thick under a small cloth, pulled 0.2 m along x over 0.5 s in frame-long moves, as the app's
    // alt+drag does: its pose follows the drag without a jump, the cloth rides on it, and released, it rests.
    Scene s = flat_cloth(5, 0.2f, 0.0155f);
    Collider board = Collider::of(BoxCollider{{0.0f, 0.005f, 0.0f}, {0.6f, 0.01f, 0.6f}});
    board.friction = 1.0f;
    s.settings.colliders.shapes = {board};
    s.settings.integration.substeps = 8;
    MassSpring sim = build_simulation(s);
    sim.run_steps(6);  // settled on the board
    const double start_x = sim.position(12).x;
    const double dt = s.settings.integration.dt;
    for (int frame = 1; frame <= 30; ++frame) {
        const glm::vec3 target(0.2f * frame / 30.0f, 0.005f, 0.0f);
        REQUIRE(sim.move_collider(0, target, dt));
        const glm::vec3 before = std::get<BoxCollider>(sim.colliders()[0].shape).center;
        CHECK(before.x == Approx(0.2f * (frame - 1) / 30.0f).margin(1e-5));  // where the last move took it
        sim.run_steps(1);
        CHECK(std::get<BoxCollider>(sim.colliders()[0].shape).center.x == Approx(target.x).margin(1e-5));
    }
    REQUIRE(sim.move_collider(0, std::get<BoxCollider>(sim.colliders()[0].shape).center, 0.0));
    CHECK(sim.settings().colliders.shapes[0].motion == ColliderMotion{});
    sim.run_steps(30);
    CHECK(std::get<BoxCollider>(sim.colliders()[0].shape).center.x == Approx(0.2f).margin(1e-5));
    // The cloth rode along: its middle moved with the board (it speeds up at mu g, 0.4 m/s being reached
    // within 0.05 s), not left behind.
    CHECK(sim.position(12).x - start_x == Approx(0.2).margin(0.03));
    CHECK_FALSE(sim.move_collider(5, glm::vec3(0.0f), 1.0));
    CHECK_FALSE(sim.move_collider(0, glm::vec3(NAN), 1.0));
}
