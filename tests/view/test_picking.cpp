// Rays through the cursor, projection back to pixels, picking a particle within a screen-space cone, and
// ray/plane intersection for dragging: each checked against the others and against hand-worked geometry.
#include "camera.hpp"
#include "layout.hpp"
#include "picking.hpp"

#include "vec_checks.hpp"

#include <catch2/catch.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

using namespace clothsim;

namespace {

using clothsim::test::check_near;
using clothsim::test::str;

std::vector<OrbitCamera> sample_cameras() {
    std::vector<OrbitCamera> cameras;
    cameras.push_back(OrbitCamera{});
    OrbitCamera c;
    c.yaw = 0.0f;
    c.pitch = 0.0f;
    cameras.push_back(c);
    c.yaw = 2.3f;
    c.pitch = -0.7f;
    c.distance = 0.4f;
    c.target = glm::vec3(1.0f, -0.5f, 2.0f);
    cameras.push_back(c);
    c.yaw = -1.1f;
    c.pitch = 1.3f;
    c.distance = 25.0f;
    c.fov_y = 1.2f;
    c.target = glm::vec3(-3.0f, 0.2f, 0.7f);
    cameras.push_back(c);
    return cameras;
}

// The point on the ray through `cursor` whose depth along the camera's view axis is `depth`.
glm::vec3 at_view_depth(const OrbitCamera& camera, glm::vec2 cursor, glm::vec2 viewport, float depth) {
    const Ray ray = ray_through(camera, cursor, viewport);
    return ray.origin + ray.direction * (depth / glm::dot(ray.direction, camera.forward()));
}

// How far (in pixels) `point` may land from its exact projection only because its coordinates are floats:
// moving each coordinate by its rounding error, seen from `depth` along the view axis, with a factor 2 for
// the stretch of pixels toward the corners and another for the arithmetic. Negligible except very near the eye.
float rounding_px(const OrbitCamera& camera, glm::vec3 point, glm::vec2 viewport) {
    const float coordinate = std::max({std::fabs(point.x), std::fabs(point.y), std::fabs(point.z)});
    const float depth = glm::dot(point - camera.eye(), camera.forward());
    const float pixels_per_tangent = 0.5f * viewport.y / std::tan(0.5f * camera.fov_y);
    return 4.0f * std::sqrt(3.0f) * std::ldexp(coordinate, -24) / depth * pixels_per_tangent;
}

// Checks that `point` projects to `pixel`, to 1e-3 px beyond what float coordinates allow.
void check_projects_to(const OrbitCamera& camera, glm::vec3 point, glm::vec2 viewport, glm::vec2 pixel) {
    const glm::vec3 p = project(camera, point, viewport);
    const double tolerance = 1e-3 + rounding_px(camera, point, viewport);
    CAPTURE(tolerance);
    CHECK(p.x == Approx(pixel.x).margin(tolerance));
    CHECK(p.y == Approx(pixel.y).margin(tolerance));
    CHECK(p.z > 0.0f);
    CHECK(p.z < 1.0f);
}

}  // namespace

TEST_CASE("picking ray through the centre pixel starts at the eye and looks forward") {
    for (const OrbitCamera& c : sample_cameras()) {
        for (glm::vec2 viewport : {glm::vec2(800.0f, 600.0f), glm::vec2(600.0f, 800.0f), glm::vec2(1920.0f, 1080.0f),
                                   glm::vec2(333.0f, 257.0f)}) {
            CAPTURE(c.yaw, c.pitch, viewport.x, viewport.y);
            const Ray ray = ray_through(c, 0.5f * viewport, viewport);
            check_near(ray.origin, c.eye(), 1e-5f * std::max(1.0f, c.distance));
            check_near(ray.direction, c.forward(), 1e-6f);
            // The target is on it.
            check_near(ray.origin + c.distance * ray.direction, c.target, 1e-5f * std::max(1.0f, c.distance));
        }
    }
}

TEST_CASE("picking rays are unit and go the way the cursor is") {
    for (const OrbitCamera& c : sample_cameras()) {
        const glm::vec2 viewport(1280.0f, 720.0f);
        for (float x : {0.0f, 1.0f, 333.3f, 640.0f, 1279.0f, 1280.0f}) {
            for (float y : {0.0f, 17.0f, 360.0f, 719.5f, 720.0f}) {
                CAPTURE(c.yaw, c.pitch, x, y);
                const Ray ray = ray_through(c, glm::vec2(x, y), viewport);
                CHECK(glm::length(ray.direction) == Approx(1.0f).epsilon(1e-6));
                CHECK(glm::dot(ray.direction, c.forward()) > 0.0f);
                // Right of centre points right, below centre (larger y) points down.
                const float r = glm::dot(ray.direction, c.right());
                const float u = glm::dot(ray.direction, c.up());
                if (x > 640.0f) CHECK(r > 0.0f);
                if (x < 640.0f) CHECK(r < 0.0f);
                if (y > 360.0f) CHECK(u < 0.0f);
                if (y < 360.0f) CHECK(u > 0.0f);
            }
        }
        // The corners of the viewport are at the edges of the field of view.
        const Ray corner = ray_through(c, glm::vec2(1280.0f, 0.0f), viewport);
        const float f = glm::dot(corner.direction, c.forward());
        const float tan_half = std::tan(0.5f * c.fov_y);
        CHECK(glm::dot(corner.direction, c.up()) / f == Approx(tan_half).epsilon(1e-5));
        CHECK(glm::dot(corner.direction, c.right()) / f == Approx(tan_half * 1280.0f / 720.0f).epsilon(1e-5));
    }
}

TEST_CASE("picking project returns the cursor pixel for every point on the ray through it") {
    for (const OrbitCamera& c : sample_cameras()) {
        for (glm::vec2 viewport : {glm::vec2(800.0f, 600.0f), glm::vec2(600.0f, 800.0f), glm::vec2(1920.0f, 1080.0f),
                                   glm::vec2(333.0f, 257.0f)}) {
            for (glm::vec2 f : {glm::vec2(0.5f, 0.5f), glm::vec2(0.0f, 0.0f), glm::vec2(1.0f, 1.0f), glm::vec2(0.1f, 0.9f),
                                glm::vec2(0.77f, 0.31f), glm::vec2(0.999f, 0.002f)}) {
                const glm::vec2 cursor = f * viewport;
                const Ray ray = ray_through(c, cursor, viewport);
                for (float t : {0.05f, 0.5f, 1.0f, 3.0f, 10.0f, 50.0f}) {
                    CAPTURE(c.yaw, c.pitch, viewport.x, viewport.y, cursor.x, cursor.y, t);
                    check_projects_to(c, ray.origin + t * ray.direction, viewport, cursor);
                }
            }
        }
    }
}

TEST_CASE("picking project of known points") {
    OrbitCamera c;
    c.yaw = 0.0f;
    c.pitch = 0.0f;
    c.target = glm::vec3(0.0f, 1.0f, 0.0f);
    c.distance = 2.0f;
    const glm::vec2 viewport(800.0f, 600.0f);
    const glm::vec3 centre = project(c, c.target, viewport);
    CHECK(centre.x == Approx(400.0f).margin(1e-3));
    CHECK(centre.y == Approx(300.0f).margin(1e-3));
    // d tan(fov/2) above the target is the top edge of the window (y = 0 at the top).
    const float half = 2.0f * std::tan(0.5f * c.fov_y);
    const glm::vec3 top = project(c, c.target + glm::vec3(0.0f, half, 0.0f), viewport);
    CHECK(top.x == Approx(400.0f).margin(1e-3));
    CHECK(top.y == Approx(0.0f).margin(1e-3));
    const glm::vec3 left = project(c, c.target + glm::vec3(-half * 800.0f / 600.0f, 0.0f, 0.0f), viewport);
    CHECK(left.x == Approx(0.0f).margin(1e-3));
    CHECK(left.y == Approx(300.0f).margin(1e-3));
    // Depth grows with distance; behind the far plane it is clipped (> 1).
    CHECK(project(c, c.target - glm::vec3(0.0f, 0.0f, 5.0f), viewport).z > centre.z);
    CHECK(project(c, c.eye() + c.forward() * (1.5f * c.far_plane), viewport).z > 1.0f);
}

TEST_CASE("picking ray and projection agree in the 3D view beside the panel") {
    struct Window {
        glm::vec2 size;
        float panel;
    };
    for (const Window& w : {Window{{1280.0f, 720.0f}, kPanelWidth}, Window{{2560.0f, 1440.0f}, 2.0f * kPanelWidth},
                            Window{{800.0f, 600.0f}, kPanelWidth}, Window{{1000.0f, 1400.0f}, kPanelWidth}}) {
        const glm::vec4 rect = view_rect(w.size, w.panel);
        REQUIRE(rect.x == w.panel);
        REQUIRE(rect.z == w.size.x - w.panel);
        const glm::vec2 offset(rect.x, rect.y), viewport(rect.z, rect.w);
        for (const OrbitCamera& c : sample_cameras()) {
            // The middle of the 3D view, not of the window, looks at the target.
            const glm::vec2 middle = offset + 0.5f * viewport;
            check_near(ray_through(c, middle - offset, viewport).direction, c.forward(), 1e-6f);
            const glm::vec3 target_px = project(c, c.target, viewport);
            CHECK(target_px.x + offset.x == Approx(middle.x).margin(1e-3));
            CHECK(target_px.y + offset.y == Approx(middle.y).margin(1e-3));

            for (glm::vec2 window_px : {offset, offset + viewport, glm::vec2(w.size.x - 1.0f, 5.0f), middle + glm::vec2(123.0f, -77.0f),
                                        glm::vec2(rect.x + 0.5f, w.size.y - 0.5f)}) {
                const Ray ray = ray_through(c, window_px - offset, viewport);
                CHECK(glm::length(ray.direction) == Approx(1.0f).epsilon(1e-6));
                for (float t : {0.1f, 1.0f, 7.0f, 30.0f}) {
                    CAPTURE(w.size.x, w.size.y, c.yaw, c.pitch, window_px.x, window_px.y, t);
                    check_projects_to(c, ray.origin + t * ray.direction, viewport, window_px - offset);
                }
            }
        }
    }
}

TEST_CASE("picking pick_particle finds nothing in nothing") {
    const Ray ray{};
    CHECK_FALSE(pick_particle(ray, std::span<const glm::vec3>(), 0.1f).has_value());
    const std::vector<glm::vec3> far_off{{5.0f, 0.0f, -1.0f}, {0.0f, -5.0f, -1.0f}};
    CHECK_FALSE(pick_particle(ray, far_off, 0.1f).has_value());
}

TEST_CASE("picking pick_particle: a particle in front hides one behind it") {
    const Ray ray{glm::vec3(1.0f, 2.0f, 3.0f), glm::normalize(glm::vec3(1.0f, -0.5f, -2.0f))};
    const glm::vec3 near_p = ray.origin + 2.0f * ray.direction;
    const glm::vec3 far_p = ray.origin + 6.0f * ray.direction;
    const glm::vec3 aside = ray.origin + 4.0f * ray.direction + glm::vec3(3.0f, 0.0f, 0.0f);  // far outside the cone
    {
        const std::vector<glm::vec3> ps{far_p, aside, near_p};
        REQUIRE(pick_particle(ray, ps, 0.02f).has_value());
        CHECK(*pick_particle(ray, ps, 0.02f) == 2);
    }
    {
        const std::vector<glm::vec3> ps{near_p, aside, far_p};
        CHECK(pick_particle(ray, ps, 0.02f) == std::optional<std::size_t>(0));
    }
    {
        // A particle well in front hides one exactly on the ray, as long as both are in the cone.
        const glm::vec3 right_on = ray.origin + 5.0f * ray.direction;
        const glm::vec3 perp = glm::normalize(glm::cross(ray.direction, glm::vec3(0.0f, 1.0f, 0.0f)));
        const glm::vec3 edge = ray.origin + 3.0f * ray.direction + perp * (0.015f * 3.0f);
        const std::vector<glm::vec3> ps{right_on, edge};
        CHECK(pick_particle(ray, ps, 0.02f) == std::optional<std::size_t>(1));
        // With a narrower cone the nearer one falls outside and the farther one is picked.
        CHECK(pick_particle(ray, ps, 0.01f) == std::optional<std::size_t>(0));
    }
}

TEST_CASE("picking pick_particle: just inside the cone is picked, just outside is not") {
    const Ray ray{glm::vec3(0.0f, 1.0f, 4.0f), glm::normalize(glm::vec3(0.2f, -0.3f, -1.0f))};
    const glm::vec3 a = glm::normalize(glm::cross(ray.direction, glm::vec3(0.0f, 1.0f, 0.0f)));
    const glm::vec3 b = glm::cross(a, ray.direction);
    const float spread = 0.01f;
    for (float depth : {0.3f, 2.0f, 9.0f}) {
        for (float angle : {0.0f, 1.0f, 2.5f, 4.0f}) {
            CAPTURE(depth, angle);
            const glm::vec3 side = std::cos(angle) * a + std::sin(angle) * b;
            const glm::vec3 on_axis = ray.origin + depth * ray.direction;
            const std::vector<glm::vec3> inside{on_axis + side * (0.99f * spread * depth)};
            const std::vector<glm::vec3> outside{on_axis + side * (1.01f * spread * depth)};
            CHECK(pick_particle(ray, inside, spread) == std::optional<std::size_t>(0));
            CHECK_FALSE(pick_particle(ray, outside, spread).has_value());
            // The outside one does not hide an inside one behind it.
            const std::vector<glm::vec3> both{outside[0], ray.origin + (depth + 1.0f) * ray.direction};
            CHECK(pick_particle(ray, both, spread) == std::optional<std::size_t>(1));
        }
    }
}

TEST_CASE("picking pick_particle never picks a particle behind the eye") {
    const Ray ray{glm::vec3(0.0f, 0.5f, 2.0f), glm::vec3(0.0f, 0.0f, -1.0f)};
    const std::vector<glm::vec3> behind{ray.origin - 0.5f * ray.direction, ray.origin - 10.0f * ray.direction,
                                        ray.origin - 0.001f * ray.direction};
    CHECK_FALSE(pick_particle(ray, behind, 0.05f).has_value());
    // A huge cone does not reach behind either, nor pick the eye itself.
    CHECK_FALSE(pick_particle(ray, behind, 100.0f).has_value());
    const std::vector<glm::vec3> at_eye{ray.origin};
    CHECK_FALSE(pick_particle(ray, at_eye, 100.0f).has_value());
    // Behind the eye is skipped, the one in front is picked although it is farther away.
    const std::vector<glm::vec3> mixed{ray.origin - 0.2f * ray.direction, ray.origin + 3.0f * ray.direction};
    CHECK(pick_particle(ray, mixed, 0.05f) == std::optional<std::size_t>(1));
}

TEST_CASE("picking pick_spread corresponds to that many pixels on screen") {
    for (const OrbitCamera& c : sample_cameras()) {
        for (glm::vec2 viewport : {glm::vec2(800.0f, 600.0f), glm::vec2(920.0f, 720.0f), glm::vec2(1920.0f, 1080.0f),
                                   glm::vec2(400.0f, 333.0f)}) {
            const glm::vec2 centre = 0.5f * viewport;
            for (glm::vec2 cursor : {centre, centre + glm::vec2(20.0f, -15.0f), centre + glm::vec2(-12.0f, 16.0f)}) {
                // Near the centre of the view: the cone is round about the ray, so off axis (at angle a) it
                // covers up to 1/cos^2(a) times as many pixels; within 25 px of the centre that stays < 0.5 px.
                const Ray ray = ray_through(c, cursor, viewport);
                for (float pixels : {1.0f, 5.0f, 10.0f, 20.0f}) {
                    const float spread = pick_spread(c, pixels, viewport.y);
                    for (float depth : {0.5f * c.distance, c.distance, 4.0f * c.distance}) {
                        for (glm::vec2 dir : {glm::vec2(1.0f, 0.0f), glm::vec2(0.0f, 1.0f), glm::vec2(-0.6f, 0.8f),
                                              glm::vec2(-0.8f, -0.6f)}) {
                            CAPTURE(c.yaw, c.pitch, viewport.x, viewport.y, cursor.x, cursor.y, pixels, depth, dir.x, dir.y);
                            const glm::vec2 in_px = cursor + (pixels - 0.5f) * dir;
                            const glm::vec2 out_px = cursor + (pixels + 0.5f) * dir;
                            const glm::vec3 in = at_view_depth(c, in_px, viewport, depth);
                            const glm::vec3 out = at_view_depth(c, out_px, viewport, depth);
                            // They do land that many pixels from the cursor.
                            const glm::vec3 in_s = project(c, in, viewport);
                            const glm::vec3 out_s = project(c, out, viewport);
                            CHECK(glm::length(glm::vec2(in_s) - in_px) < 1e-2f);
                            CHECK(glm::length(glm::vec2(out_s) - out_px) < 1e-2f);

                            const std::vector<glm::vec3> in_v{in};
                            const std::vector<glm::vec3> out_v{out};
                            CHECK(pick_particle(ray, in_v, spread) == std::optional<std::size_t>(0));
                            CHECK_FALSE(pick_particle(ray, out_v, spread).has_value());
                        }
                    }
                }
            }
        }
    }
    // Linear in pixels, independent of the camera's distance.
    OrbitCamera c;
    const float one = pick_spread(c, 1.0f, 600.0f);
    CHECK(pick_spread(c, 10.0f, 600.0f) == Approx(10.0f * one).epsilon(1e-6));
    CHECK(pick_spread(c, 10.0f, 1200.0f) == Approx(5.0f * one).epsilon(1e-6));
    c.distance = 50.0f;
    CHECK(pick_spread(c, 1.0f, 600.0f) == Approx(one).epsilon(1e-6));
}

TEST_CASE("picking intersect_plane") {
    SECTION("hits the point where the ray meets the plane") {
        const Ray ray{glm::vec3(0.0f, 2.0f, 0.0f), glm::normalize(glm::vec3(1.0f, -1.0f, 0.0f))};
        const auto hit = intersect_plane(ray, glm::vec3(5.0f, 0.0f, -3.0f), glm::vec3(0.0f, 1.0f, 0.0f));
        REQUIRE(hit.has_value());
        check_near(*hit, glm::vec3(2.0f, 0.0f, 0.0f), 1e-5f);
        // The side the normal points to does not matter, nor its length.
        const auto flipped = intersect_plane(ray, glm::vec3(5.0f, 0.0f, -3.0f), glm::vec3(0.0f, -3.0f, 0.0f));
        REQUIRE(flipped.has_value());
        check_near(*flipped, glm::vec3(2.0f, 0.0f, 0.0f), 1e-5f);
    }
    SECTION("an oblique plane: the hit is on the plane and on the ray") {
        const Ray ray{glm::vec3(0.3f, -0.2f, 1.5f), glm::normalize(glm::vec3(-0.4f, 0.5f, -1.0f))};
        const glm::vec3 point(0.1f, 0.4f, -0.8f), normal = glm::normalize(glm::vec3(0.3f, -0.2f, 0.9f));
        const auto hit = intersect_plane(ray, point, normal);
        REQUIRE(hit.has_value());
        CHECK(glm::dot(*hit - point, normal) == Approx(0.0f).margin(1e-5));
        const glm::vec3 along = *hit - ray.origin;
        CHECK(glm::length(along - glm::dot(along, ray.direction) * ray.direction) == Approx(0.0f).margin(1e-5));
        CHECK(glm::dot(along, ray.direction) > 0.0f);
    }
    SECTION("a ray starting on the plane hits at its origin") {
        const Ray ray{glm::vec3(1.0f, 0.0f, 1.0f), glm::normalize(glm::vec3(0.0f, 1.0f, -1.0f))};
        const auto hit = intersect_plane(ray, glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f));
        REQUIRE(hit.has_value());
        check_near(*hit, ray.origin, 1e-6f);
    }
    SECTION("parallel rays miss") {
        const Ray ray{glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(1.0f, 0.0f, 0.0f)};
        CHECK_FALSE(intersect_plane(ray, glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f)).has_value());
        // Even when the ray lies in the plane.
        CHECK_FALSE(intersect_plane(ray, glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f)).has_value());
        const Ray oblique{glm::vec3(2.0f), glm::normalize(glm::vec3(1.0f, 1.0f, 0.0f))};
        CHECK_FALSE(intersect_plane(oblique, glm::vec3(0.0f), glm::normalize(glm::vec3(1.0f, -1.0f, 0.0f))).has_value());
    }
    SECTION("a plane behind the origin is missed") {
        const Ray ray{glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f)};
        CHECK_FALSE(intersect_plane(ray, glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f)).has_value());
        CHECK_FALSE(intersect_plane(ray, glm::vec3(0.0f), glm::vec3(0.0f, -1.0f, 0.0f)).has_value());
        // Turned around, it is hit.
        const Ray down{ray.origin, -ray.direction};
        const auto hit = intersect_plane(down, glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f));
        REQUIRE(hit.has_value());
        check_near(*hit, glm::vec3(0.0f), 1e-6f);
    }
}

TEST_CASE("picking a 5x5 grid through a framed camera: the pixel of particle k picks k") {
    struct Grid {
        glm::vec3 origin, u, v;  // particle (i, j) at origin + i u + j v
    };
    // A hanging cloth (vertical), a cloth lying flat, and a tilted one off the origin.
    const std::array<Grid, 3> grids{{
        {glm::vec3(-0.5f, 1.5f, 0.0f), glm::vec3(0.25f, 0.0f, 0.0f), glm::vec3(0.0f, -0.25f, 0.0f)},
        {glm::vec3(-0.5f, 0.3f, -0.5f), glm::vec3(0.25f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, 0.25f)},
        {glm::vec3(2.0f, 0.5f, 1.0f), glm::vec3(0.1f, 0.05f, 0.0f), glm::vec3(0.0f, 0.08f, -0.1f)},
    }};
    for (const Grid& g : grids) {
        std::vector<glm::vec3> positions;
        for (int j = 0; j < 5; ++j)
            for (int i = 0; i < 5; ++i)
                positions.push_back(g.origin + static_cast<float>(i) * g.u + static_cast<float>(j) * g.v);
        glm::vec3 lo = positions[0], hi = positions[0];
        for (const glm::vec3& p : positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        for (glm::vec2 window : {glm::vec2(1280.0f, 720.0f), glm::vec2(800.0f, 900.0f)}) {
            const glm::vec4 rect = view_rect(window, kPanelWidth);
            const glm::vec2 offset(rect.x, rect.y), viewport(rect.z, rect.w);
            // Turned either way, though not so far that the cloth is seen edge-on (where particles do hide others).
            for (float yaw_turn : {0.0f, 0.6f, -0.3f}) {
                OrbitCamera c = framed_camera(lo, hi, viewport.x / viewport.y);
                c.orbit(glm::vec2(yaw_turn / 0.008f, 0.0f));
                const float spread = pick_spread(c, 10.0f, viewport.y);
                for (std::size_t k = 0; k < positions.size(); ++k) {
                    CAPTURE(g.origin.x, window.x, yaw_turn, k);
                    const glm::vec3 s = project(c, positions[k], viewport);
                    const glm::vec2 window_px = glm::vec2(s) + offset;
                    // Every particle is in the view.
                    CHECK(window_px.x >= rect.x);
                    CHECK(window_px.x <= rect.x + rect.z);
                    CHECK(window_px.y >= 0.0f);
                    CHECK(window_px.y <= rect.w);
                    const Ray ray = ray_through(c, window_px - offset, viewport);
                    CHECK(pick_particle(ray, positions, spread) == std::optional<std::size_t>(k));
                    // A few pixels off still picks it.
                    const Ray off = ray_through(c, window_px - offset + glm::vec2(3.0f, -4.0f), viewport);
                    CHECK(pick_particle(off, positions, spread) == std::optional<std::size_t>(k));
                    // Dragging: the plane through the particle facing the camera, hit by the same ray, is the particle.
                    const auto grab = intersect_plane(ray, positions[k], c.forward());
                    REQUIRE(grab.has_value());
                    check_near(*grab, positions[k], 1e-4f);
                }
                // Between particles (beyond the 10 px tolerance from every one) nothing is picked.
                const glm::vec3 gap = g.origin + 1.5f * g.u + 1.5f * g.v;
                const Ray between = ray_through(c, glm::vec2(project(c, gap, viewport)), viewport);
                CHECK_FALSE(pick_particle(between, positions, spread).has_value());
            }
        }
    }
}

TEST_CASE("picking a dense cloth: the pixel of a particle picks that particle, not a neighbour nearer the eye") {
    // Curtain-like: 40 x 48 over 1.2 m, neighbours 3 cm apart (about 7 px at 1280 x 720), seen from the
    // side and from above, so a 10 px cone holds several particles at various depths.
    std::vector<glm::vec3> positions;
    const int rows = 40, cols = 48;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            positions.push_back({-0.6f + 0.025f * static_cast<float>(c), 2.0f - 0.025f * static_cast<float>(r),
                                 0.002f * static_cast<float>(r % 3)});
    glm::vec3 lo = positions[0], hi = positions[0];
    for (const glm::vec3& p : positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const glm::vec4 rect = view_rect(glm::vec2(1280.0f, 720.0f), kPanelWidth);
    const glm::vec2 viewport(rect.z, rect.w);
    for (glm::vec2 turn : {glm::vec2(0.0f), glm::vec2(60.0f, 0.0f), glm::vec2(-40.0f, 30.0f)}) {
        OrbitCamera c = framed_camera(lo, hi, viewport.x / viewport.y);
        c.orbit(turn);
        const float spread = pick_spread(c, 10.0f, viewport.y);
        long long wrong = 0;
        for (std::size_t k = 0; k < positions.size(); ++k) {
            const Ray ray = ray_through(c, glm::vec2(project(c, positions[k], viewport)), viewport);
            wrong += pick_particle(ray, positions, spread) != std::optional<std::size_t>(k);
        }
        CAPTURE(turn.x, turn.y);
        CHECK(wrong == 0);
    }
}

TEST_CASE("picking a layer behind the visible one is not picked through it") {
    // A dense front sheet (1 cm apart, closer than the 10 px cone) and a coarse one 0.5 m behind; the cursor
    // on a back particle's pixel, with the front sheet covering it, picks the front sheet.
    std::vector<glm::vec3> positions;
    for (int r = 0; r < 10; ++r)
        for (int c = 0; c < 10; ++c) positions.push_back({0.05f * static_cast<float>(c), 0.05f * static_cast<float>(r), -0.5f});
    const std::size_t front_begin = positions.size();
    for (int r = 0; r < 50; ++r)
        for (int c = 0; c < 50; ++c) positions.push_back({0.01f * static_cast<float>(c), 0.01f * static_cast<float>(r), 0.0f});
    OrbitCamera cam;  // in front of the sheets, looking along -z
    cam.target = {0.245f, 0.245f, -0.25f};
    cam.distance = 1.5f;
    cam.yaw = 0.0f;
    cam.pitch = 0.0f;
    const glm::vec2 viewport(1280.0f, 720.0f);
    const float spread = pick_spread(cam, 10.0f, viewport.y);
    for (std::size_t back : {std::size_t(55), std::size_t(33), std::size_t(77)}) {
        const Ray ray = ray_through(cam, glm::vec2(project(cam, positions[back], viewport)), viewport);
        const auto hit = pick_particle(ray, positions, spread);
        REQUIRE(hit.has_value());
        CHECK(*hit >= front_begin);
    }
}
