// An orbit camera (Blender-style): it circles a target; drag orbits, pans, the wheel zooms.
// Pure maths on GLM, no OpenGL: the picking and camera tests run without a window.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace clothsim {

struct OrbitCamera {
    glm::vec3 target{0.0f, 0.8f, 0.0f};  // m: the point orbited and looked at
    float distance = 3.0f;               // m from target to eye
    float yaw = 0.5f;                    // rad about +y; 0 looks along -z
    float pitch = 0.3f;                  // rad above the horizon, kept within +-89 degrees
    float fov_y = 0.7854f;               // rad: vertical field of view (45 degrees)
    float near_plane = 0.01f;            // m
    float far_plane = 200.0f;            // m

    glm::vec3 eye() const;
    glm::vec3 forward() const;  // unit, from eye toward target
    glm::vec3 right() const;    // unit, screen right
    glm::vec3 up() const;       // unit, screen up
    glm::mat4 view() const;
    glm::mat4 projection(float aspect) const;

    // Mouse gestures, in window pixels: orbiting 1 px turns by `radians_per_pixel`; panning moves the target
    // so the point at the target's depth follows the cursor; each wheel step zooms by 10%.
    void orbit(glm::vec2 delta_px, float radians_per_pixel = 0.008f);
    void pan(glm::vec2 delta_px, float viewport_height_px);
    void zoom(float wheel_steps);
    // Keeps the eye above the plane y = height (the ground): the target is raised to it, and the pitch to
    // the lowest that leaves the eye 1 cm above it.
    void keep_above(float height);
    // Looks at the centre of a box from the current direction, from just far enough to see all of it.
    void frame(glm::vec3 box_min, glm::vec3 box_max, float aspect);
};

// The camera the app starts with (and returns to on "reset camera"): the default direction, framing the box.
OrbitCamera framed_camera(glm::vec3 box_min, glm::vec3 box_max, float aspect);

struct Ray {
    glm::vec3 origin{0.0f};
    glm::vec3 direction{0.0f, 0.0f, -1.0f};  // unit
};

// The ray through a cursor position (pixels, origin at the window's top-left).
Ray ray_through(const OrbitCamera& camera, glm::vec2 cursor_px, glm::vec2 viewport_px);
// Where a point lands on screen (pixels, top-left origin); z is the depth in [0, 1], > 1 or < 0 if clipped.
glm::vec3 project(const OrbitCamera& camera, glm::vec3 point, glm::vec2 viewport_px);

}  // namespace clothsim
