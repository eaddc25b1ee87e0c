// The orbit camera: its frame (eye, forward, right, up), the view and projection matrices, and the mouse
// gestures (orbit, pan, zoom) and framing, checked against geometry worked out independently of the code.
#include "camera.hpp"

#include "vec_checks.hpp"

#include <catch2/catch.hpp>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

using namespace clothsim;

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

using clothsim::test::check_near;
using clothsim::test::str;

glm::vec3 transform_point(const glm::mat4& m, glm::vec3 p) {
    const glm::vec4 h = m * glm::vec4(p, 1.0f);
    return glm::vec3(h) / h.w;
}

bool finite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

// A spread of camera poses: default, level, looking up and down, every quadrant of yaw, near and far.
std::vector<OrbitCamera> sample_cameras() {
    std::vector<OrbitCamera> cameras;
    cameras.push_back(OrbitCamera{});
    const std::array<float, 6> yaws{0.0f, 0.5f, 1.9f, -2.4f, 3.0f, 7.0f};
    const std::array<float, 5> pitches{0.0f, 0.3f, -0.6f, 1.2f, -1.5f};
    const std::array<float, 3> distances{0.2f, 3.0f, 40.0f};
    int i = 0;
    for (float yaw : yaws)
        for (float pitch : pitches) {
            OrbitCamera c;
            c.yaw = yaw;
            c.pitch = pitch;
            c.distance = distances[static_cast<std::size_t>(i) % distances.size()];
            c.target = glm::vec3(0.3f * static_cast<float>(i % 5) - 0.6f, 0.8f + 0.1f * static_cast<float>(i % 3),
                                 -0.2f * static_cast<float>(i % 4));
            cameras.push_back(c);
            ++i;
        }
    return cameras;
}

}  // namespace

TEST_CASE("camera eye is at distance from the target and forward points from the eye to the target") {
    for (const OrbitCamera& c : sample_cameras()) {
        CAPTURE(c.yaw, c.pitch, c.distance);
        CHECK(glm::length(c.eye() - c.target) == Approx(c.distance).epsilon(1e-5));
        CHECK(glm::length(c.forward()) == Approx(1.0f).epsilon(1e-6));
        check_near(c.forward(), glm::normalize(c.target - c.eye()), 1e-5f);
        // Positive pitch is above the horizon: the eye is higher than the target and looks down.
        if (c.pitch > 0.0f) CHECK(c.eye().y > c.target.y);
        if (c.pitch < 0.0f) CHECK(c.eye().y < c.target.y);
        CHECK(c.eye().y - c.target.y == Approx(c.distance * std::sin(c.pitch)).margin(1e-5));
    }
}

TEST_CASE("camera right, up and forward are orthonormal and right-handed") {
    for (const OrbitCamera& c : sample_cameras()) {
        CAPTURE(c.yaw, c.pitch);
        const glm::vec3 r = c.right(), u = c.up(), f = c.forward();
        CHECK(glm::length(r) == Approx(1.0f).epsilon(1e-5));
        CHECK(glm::length(u) == Approx(1.0f).epsilon(1e-5));
        CHECK(glm::dot(r, u) == Approx(0.0f).margin(1e-5));
        CHECK(glm::dot(r, f) == Approx(0.0f).margin(1e-5));
        CHECK(glm::dot(u, f) == Approx(0.0f).margin(1e-5));
        // OpenGL view space: x right, y up, z toward the viewer (= -forward).
        check_near(glm::cross(r, u), -f, 1e-5f);
        // Screen right stays level (no roll) and screen up points to the sky.
        CHECK(r.y == Approx(0.0f).margin(1e-6));
        CHECK(u.y > 0.0f);
    }
}

TEST_CASE("camera yaw 0 and pitch 0 look along -z, yaw turns about +y") {
    OrbitCamera c;
    c.target = glm::vec3(1.0f, 2.0f, 3.0f);
    c.distance = 4.0f;
    c.yaw = 0.0f;
    c.pitch = 0.0f;
    check_near(c.forward(), glm::vec3(0.0f, 0.0f, -1.0f), 1e-6f);
    check_near(c.right(), glm::vec3(1.0f, 0.0f, 0.0f), 1e-6f);
    check_near(c.up(), glm::vec3(0.0f, 1.0f, 0.0f), 1e-6f);
    check_near(c.eye(), glm::vec3(1.0f, 2.0f, 7.0f), 1e-5f);

    // A quarter turn counter-clockwise about +y (seen from above) turns -z into -x.
    c.yaw = 0.5f * kPi;
    check_near(c.forward(), glm::vec3(-1.0f, 0.0f, 0.0f), 1e-6f);
    check_near(c.right(), glm::vec3(0.0f, 0.0f, -1.0f), 1e-6f);
    check_near(c.eye(), glm::vec3(5.0f, 2.0f, 3.0f), 1e-5f);

    // Pitching up by 45 degrees from level: looking down at 45 degrees.
    c.yaw = 0.0f;
    c.pitch = 0.25f * kPi;
    const float h = std::sqrt(0.5f);
    check_near(c.forward(), glm::vec3(0.0f, -h, -h), 1e-6f);
    check_near(c.up(), glm::vec3(0.0f, h, -h), 1e-6f);
}

TEST_CASE("camera view maps the target to (0,0,-distance) and the eye to the origin") {
    for (const OrbitCamera& c : sample_cameras()) {
        CAPTURE(c.yaw, c.pitch, c.distance);
        const glm::mat4 v = c.view();
        const float tol = 1e-5f * std::max(1.0f, c.distance);
        check_near(transform_point(v, c.target), glm::vec3(0.0f, 0.0f, -c.distance), tol);
        check_near(transform_point(v, c.eye()), glm::vec3(0.0f), tol);
        // The camera's axes map to the view-space axes.
        check_near(transform_point(v, c.target + c.right()), glm::vec3(1.0f, 0.0f, -c.distance), tol);
        check_near(transform_point(v, c.target + c.up()), glm::vec3(0.0f, 1.0f, -c.distance), tol);
        check_near(transform_point(v, c.eye() + c.forward()), glm::vec3(0.0f, 0.0f, -1.0f), tol);
        // A rigid motion: lengths are kept.
        const glm::vec3 a(0.3f, -1.0f, 2.0f), b(-0.7f, 0.4f, 0.1f);
        CHECK(glm::length(transform_point(v, a) - transform_point(v, b)) == Approx(glm::length(a - b)).epsilon(1e-5));
    }
}

TEST_CASE("camera projection maps the target to the NDC centre and the field of view to the NDC edges") {
    for (const OrbitCamera& c : sample_cameras()) {
        for (float aspect : {0.5f, 1.0f, 16.0f / 9.0f, 3.0f}) {
            CAPTURE(c.yaw, c.pitch, c.distance, aspect);
            const glm::mat4 pv = c.projection(aspect) * c.view();
            const glm::vec3 centre = transform_point(pv, c.target);
            CHECK(centre.x == Approx(0.0f).margin(1e-5));
            CHECK(centre.y == Approx(0.0f).margin(1e-5));
            CHECK(centre.z > -1.0f);
            CHECK(centre.z < 1.0f);
            // The top edge of the view at the target's depth is d tan(fov/2) above it; the right edge is
            // aspect times as far to the side.
            const float half_height = c.distance * std::tan(0.5f * c.fov_y);
            const glm::vec3 top = transform_point(pv, c.target + c.up() * half_height);
            CHECK(top.x == Approx(0.0f).margin(1e-5));
            CHECK(top.y == Approx(1.0f).epsilon(1e-5));
            const glm::vec3 side = transform_point(pv, c.target + c.right() * (half_height * aspect));
            CHECK(side.x == Approx(1.0f).epsilon(1e-5));
            CHECK(side.y == Approx(0.0f).margin(1e-5));
        }
    }
    // OpenGL depth: the near plane maps to -1 and the far plane to +1.
    OrbitCamera c;
    const glm::mat4 pv = c.projection(1.5f) * c.view();
    CHECK(transform_point(pv, c.eye() + c.forward() * c.near_plane).z == Approx(-1.0f).margin(1e-4));
    CHECK(transform_point(pv, c.eye() + c.forward() * c.far_plane).z == Approx(1.0f).margin(1e-4));
}

TEST_CASE("camera orbit: a horizontal drag only changes yaw, a vertical one only pitch") {
    OrbitCamera c;
    c.target = glm::vec3(0.2f, 0.5f, -0.3f);
    const OrbitCamera before = c;

    c.orbit(glm::vec2(25.0f, 0.0f));
    CHECK(c.yaw == Approx(before.yaw - 25.0f * 0.008f).epsilon(1e-6));
    CHECK(c.pitch == before.pitch);
    CHECK(c.distance == before.distance);
    check_near(c.target, before.target, 0.0f);
    // The eye stays on the same horizontal circle around the target.
    CHECK(glm::length(c.eye() - c.target) == Approx(before.distance).epsilon(1e-5));
    CHECK(c.eye().y == Approx(before.eye().y).margin(1e-5));
    CHECK(c.eye() != before.eye());

    c = before;
    c.orbit(glm::vec2(-40.0f, 0.0f), 0.01f);
    CHECK(c.yaw == Approx(before.yaw + 0.4f).epsilon(1e-6));
    CHECK(c.pitch == before.pitch);

    c = before;
    c.orbit(glm::vec2(0.0f, 30.0f));
    CHECK(c.yaw == before.yaw);
    CHECK(c.pitch == Approx(before.pitch + 30.0f * 0.008f).epsilon(1e-6));
    CHECK(c.distance == before.distance);
    check_near(c.target, before.target, 0.0f);
    // Dragging down raises the eye (looks down more steeply).
    CHECK(c.eye().y > before.eye().y);
}

TEST_CASE("camera orbit clamps pitch below 90 degrees") {
    for (float drag : {1e3f, 1e5f, -1e3f, -1e5f}) {
        CAPTURE(drag);
        OrbitCamera c;
        c.orbit(glm::vec2(0.0f, drag));
        CHECK(std::fabs(c.pitch) < 0.5f * kPi);
        CHECK(std::fabs(c.pitch) > 85.0f * kPi / 180.0f);  // it does reach (close to) straight down / up
        CHECK((c.pitch > 0.0f) == (drag > 0.0f));
        CHECK(finite(c.view()));
        CHECK(finite(c.projection(1.5f) * c.view()));
        CHECK(glm::length(c.right()) == Approx(1.0f).epsilon(1e-4));
        CHECK(glm::dot(c.right(), c.up()) == Approx(0.0f).margin(1e-4));
        CHECK(glm::length(c.eye() - c.target) == Approx(c.distance).epsilon(1e-5));
        // The view still maps the target onto the view axis.
        const glm::vec3 t = transform_point(c.view(), c.target);
        CHECK(t.x == Approx(0.0f).margin(1e-4));
        CHECK(t.y == Approx(0.0f).margin(1e-4));
        CHECK(t.z == Approx(-c.distance).epsilon(1e-4));
        // Many further drags the same way keep it there.
        for (int i = 0; i < 10; ++i) c.orbit(glm::vec2(3.0f, drag));
        CHECK(std::fabs(c.pitch) < 0.5f * kPi);
        CHECK(finite(c.view()));
    }
}

TEST_CASE("camera zoom scales the distance by 0.9 per wheel step, within [0.05, far/2]") {
    OrbitCamera c;
    c.distance = 3.0f;
    c.zoom(1.0f);
    CHECK(c.distance == Approx(2.7f).epsilon(1e-6));
    c.zoom(-1.0f);
    CHECK(c.distance == Approx(3.0f).epsilon(1e-6));
    c.zoom(-1.0f);
    CHECK(c.distance == Approx(3.0f / 0.9f).epsilon(1e-6));
    c.distance = 3.0f;
    c.zoom(3.0f);
    CHECK(c.distance == Approx(3.0f * 0.729f).epsilon(1e-5));
    c.distance = 3.0f;
    c.zoom(0.5f);  // trackpads send fractional steps
    CHECK(c.distance == Approx(3.0f * std::sqrt(0.9f)).epsilon(1e-6));

    // Zoom changes nothing but the distance.
    const OrbitCamera before = c;
    c.zoom(2.0f);
    CHECK(c.yaw == before.yaw);
    CHECK(c.pitch == before.pitch);
    check_near(c.target, before.target, 0.0f);

    c.zoom(1000.0f);
    CHECK(c.distance == Approx(0.05f).epsilon(1e-6));
    c.zoom(1.0f);
    CHECK(c.distance == Approx(0.05f).epsilon(1e-6));
    c.zoom(-1000.0f);
    CHECK(c.distance == Approx(100.0f).epsilon(1e-6));  // half the default far plane of 200 m
    c.zoom(-1.0f);
    CHECK(c.distance == Approx(100.0f).epsilon(1e-6));

    c.far_plane = 20.0f;
    c.distance = 9.5f;
    c.zoom(-1.0f);
    CHECK(c.distance == Approx(10.0f).epsilon(1e-6));
}

TEST_CASE("camera pan moves the target by the world size of a pixel at the target's depth") {
    for (OrbitCamera c : sample_cameras()) {
        for (float height : {600.0f, 1080.0f}) {
            CAPTURE(c.yaw, c.pitch, c.distance, height);
            const OrbitCamera before = c;
            const float per_pixel = 2.0f * c.distance * std::tan(0.5f * c.fov_y) / height;
            c.pan(glm::vec2(12.0f, -7.0f), height);
            // Dragging right moves the camera left (the scene follows the cursor right); dragging up (negative
            // y in window pixels) moves it down.
            const glm::vec3 expected = before.target - before.right() * (12.0f * per_pixel) - before.up() * (7.0f * per_pixel);
            check_near(c.target, expected, 1e-5f * std::max(1.0f, c.distance));
            CHECK(glm::length(c.target - before.target) == Approx(std::hypot(12.0f, 7.0f) * per_pixel).epsilon(1e-4));
            CHECK(c.distance == before.distance);
            CHECK(c.yaw == before.yaw);
            CHECK(c.pitch == before.pitch);
            c = before;
        }
    }
}

TEST_CASE("camera pan keeps the point under the cursor under it") {
    for (OrbitCamera c : sample_cameras()) {
        for (glm::vec2 viewport : {glm::vec2(800.0f, 600.0f), glm::vec2(920.0f, 720.0f), glm::vec2(500.0f, 900.0f)}) {
            for (glm::vec2 cursor : {0.5f * viewport, glm::vec2(100.0f, 80.0f), viewport - glm::vec2(30.0f, 50.0f)}) {
                for (glm::vec2 delta : {glm::vec2(15.0f, 0.0f), glm::vec2(0.0f, -22.0f), glm::vec2(-60.0f, 45.0f)}) {
                    CAPTURE(c.yaw, c.pitch, c.distance, viewport.x, viewport.y, cursor.x, cursor.y, delta.x, delta.y);
                    // The point under the cursor in the plane through the target facing the camera.
                    const Ray ray = ray_through(c, cursor, viewport);
                    const float t = c.distance / glm::dot(ray.direction, c.forward());
                    const glm::vec3 grabbed = ray.origin + t * ray.direction;
                    const glm::vec3 p0 = project(c, grabbed, viewport);
                    CHECK(p0.x == Approx(cursor.x).margin(1e-2));
                    CHECK(p0.y == Approx(cursor.y).margin(1e-2));

                    OrbitCamera moved = c;
                    moved.pan(delta, viewport.y);
                    const glm::vec3 p1 = project(moved, grabbed, viewport);
                    CHECK(p1.x == Approx(cursor.x + delta.x).margin(1e-2));
                    CHECK(p1.y == Approx(cursor.y + delta.y).margin(1e-2));
                }
            }
        }
    }
}

TEST_CASE("camera frame centres the box and keeps all of it in view") {
    struct Box {
        glm::vec3 lo, hi;
    };
    const std::array<Box, 4> boxes{{
        {glm::vec3(-0.5f, 0.0f, -0.5f), glm::vec3(0.5f, 1.0f, 0.5f)},
        {glm::vec3(-2.0f, 0.3f, -0.1f), glm::vec3(2.0f, 0.5f, 0.1f)},     // wide and flat
        {glm::vec3(0.0f, 0.0f, 0.0f), glm::vec3(0.2f, 3.0f, 0.2f)},       // tall and thin
        {glm::vec3(10.0f, -1.0f, 4.0f), glm::vec3(12.0f, 1.0f, 4.0f)},    // off the origin, no depth
    }};
    for (const Box& box : boxes) {
        for (float aspect : {0.5f, 1.0f, 16.0f / 9.0f, 3.0f}) {
            for (const OrbitCamera& start : sample_cameras()) {
                CAPTURE(box.lo.x, box.hi.x, aspect, start.yaw, start.pitch);
                OrbitCamera c = start;
                c.frame(box.lo, box.hi, aspect);
                check_near(c.target, 0.5f * (box.lo + box.hi), 1e-6f);
                CHECK(c.yaw == start.yaw);  // from the current direction
                CHECK(c.pitch == start.pitch);

                const glm::vec2 viewport(600.0f * aspect, 600.0f);
                for (int corner = 0; corner < 8; ++corner) {
                    const glm::vec3 p((corner & 1) ? box.hi.x : box.lo.x, (corner & 2) ? box.hi.y : box.lo.y,
                                      (corner & 4) ? box.hi.z : box.lo.z);
                    const glm::vec3 s = project(c, p, viewport);
                    CAPTURE(corner, s.x, s.y, s.z);
                    CHECK(s.x >= 0.0f);
                    CHECK(s.x <= viewport.x);
                    CHECK(s.y >= 0.0f);
                    CHECK(s.y <= viewport.y);
                    CHECK(s.z > 0.0f);
                    CHECK(s.z < 1.0f);
                }

                // Just far enough: the bounding sphere touches the edge of the view in the narrower direction,
                // i.e. the ray through the middle of that edge passes at exactly one radius from the centre.
                const float radius = 0.5f * glm::length(box.hi - box.lo);
                const glm::vec2 edge = aspect >= 1.0f ? glm::vec2(0.5f * viewport.x, 0.0f) : glm::vec2(0.0f, 0.5f * viewport.y);
                const Ray ray = ray_through(c, edge, viewport);
                const glm::vec3 to_centre = c.target - ray.origin;
                const float miss = glm::length(to_centre - glm::dot(to_centre, ray.direction) * ray.direction);
                CHECK(miss == Approx(radius).epsilon(1e-3));
            }
        }
    }
}

TEST_CASE("camera frame of a degenerate box stays finite") {
    OrbitCamera c;
    c.frame(glm::vec3(1.0f, 2.0f, 3.0f), glm::vec3(1.0f, 2.0f, 3.0f), 1.5f);
    check_near(c.target, glm::vec3(1.0f, 2.0f, 3.0f), 0.0f);
    CHECK(std::isfinite(c.distance));
    CHECK(c.distance >= 0.05f);
    CHECK(c.distance > c.near_plane);
    CHECK(finite(c.projection(1.5f) * c.view()));

    // A huge box is clamped to half the far plane.
    c.frame(glm::vec3(-1e4f), glm::vec3(1e4f), 1.0f);
    CHECK(c.distance == Approx(0.5f * c.far_plane));
}

TEST_CASE("camera framed_camera is the default camera framed") {
    const glm::vec3 lo(-0.8f, 0.1f, -0.4f), hi(0.6f, 1.7f, 0.3f);
    for (float aspect : {0.5f, 1.0f, 16.0f / 9.0f, 3.0f}) {
        CAPTURE(aspect);
        OrbitCamera expected;
        expected.frame(lo, hi, aspect);
        const OrbitCamera c = framed_camera(lo, hi, aspect);
        const OrbitCamera defaults;
        CHECK(c.yaw == defaults.yaw);
        CHECK(c.pitch == defaults.pitch);
        CHECK(c.fov_y == defaults.fov_y);
        CHECK(c.near_plane == defaults.near_plane);
        CHECK(c.far_plane == defaults.far_plane);
        CHECK(c.target == expected.target);
        CHECK(c.distance == expected.distance);
        CHECK(c.view() == expected.view());
        check_near(c.target, 0.5f * (lo + hi), 1e-6f);
    }
}

TEST_CASE("camera keep_above: orbiting or panning down never takes the eye under the ground") {
    OrbitCamera c;
    c.target = {0.0f, 0.5f, 0.0f};
    c.distance = 3.0f;
    for (int i = 0; i < 200; ++i) {
        c.orbit(glm::vec2(3.0f, -20.0f));  // drag up: the eye goes down
        c.keep_above(0.0f);
        CHECK(c.eye().y >= 0.0f);
    }
    CHECK(c.eye().y == Approx(0.01f).margin(1e-4));  // it ends just above the ground, looking level-ish
    c.pan(glm::vec2(0.0f, -5000.0f), 720.0f);  // pan far down: the target goes under
    c.keep_above(0.0f);
    CHECK(c.target.y >= 0.0f);
    CHECK(c.eye().y >= 0.0f);
    // Above the ground nothing changes.
    OrbitCamera high;
    const OrbitCamera before = high;
    high.keep_above(-1.0f);
    CHECK(high.pitch == before.pitch);
    CHECK(high.target == before.target);
}
