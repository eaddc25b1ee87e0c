#include "camera.hpp"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace clothsim {

namespace {
constexpr float kMaxPitch = 1.5533f;  // 89 degrees: never look straight down, where yaw degenerates
}

glm::vec3 OrbitCamera::forward() const {
    return {-std::cos(pitch) * std::sin(yaw), -std::sin(pitch), -std::cos(pitch) * std::cos(yaw)};
}

glm::vec3 OrbitCamera::eye() const { return target - forward() * distance; }

glm::vec3 OrbitCamera::right() const { return glm::normalize(glm::cross(forward(), glm::vec3(0.0f, 1.0f, 0.0f))); }

glm::vec3 OrbitCamera::up() const { return glm::cross(right(), forward()); }

glm::mat4 OrbitCamera::view() const { return glm::lookAt(eye(), target, glm::vec3(0.0f, 1.0f, 0.0f)); }

glm::mat4 OrbitCamera::projection(float aspect) const {
    return glm::perspective(fov_y, std::max(aspect, 1e-3f), near_plane, far_plane);
}

void OrbitCamera::orbit(glm::vec2 delta_px, float radians_per_pixel) {
    yaw -= delta_px.x * radians_per_pixel;
    pitch = std::clamp(pitch + delta_px.y * radians_per_pixel, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(glm::vec2 delta_px, float viewport_height_px) {
    // Height of the view at the target's depth, in metres, over the viewport's height in pixels.
    const float metres_per_pixel = 2.0f * distance * std::tan(0.5f * fov_y) / std::max(viewport_height_px, 1.0f);
    target += (-delta_px.x * right() + delta_px.y * up()) * metres_per_pixel;
}

void OrbitCamera::zoom(float wheel_steps) {
    distance = std::clamp(distance * std::pow(0.9f, wheel_steps), 0.05f, 0.5f * far_plane);
}

void OrbitCamera::keep_above(float height) {
    target.y = std::max(target.y, height);
    // eye.y = target.y + distance sin(pitch)
    const float lowest = std::asin(std::clamp((height + 0.01f - target.y) / distance, -1.0f, 1.0f));
    pitch = std::clamp(std::max(pitch, lowest), -kMaxPitch, kMaxPitch);
}

void OrbitCamera::frame(glm::vec3 box_min, glm::vec3 box_max, float aspect) {
    target = 0.5f * (box_min + box_max);
    const float radius = std::max(0.5f * glm::length(box_max - box_min), 0.01f);
    // The bounding sphere fits in the narrower of the two fields of view.
    const float half_fov = 0.5f * fov_y;
    const float half_fov_x = std::atan(std::tan(half_fov) * std::max(aspect, 1e-3f));
    distance = std::clamp(radius / std::sin(std::min(half_fov, half_fov_x)), 0.05f, 0.5f * far_plane);
}

OrbitCamera framed_camera(glm::vec3 box_min, glm::vec3 box_max, float aspect) {
    OrbitCamera camera;
    camera.frame(box_min, box_max, aspect);
    return camera;
}

Ray ray_through(const OrbitCamera& camera, glm::vec2 cursor_px, glm::vec2 viewport_px) {
    const float aspect = viewport_px.x / std::max(viewport_px.y, 1.0f);
    // Normalised device coordinates: x right, y up, in [-1, 1].
    const float ndc_x = 2.0f * cursor_px.x / viewport_px.x - 1.0f;
    const float ndc_y = 1.0f - 2.0f * cursor_px.y / viewport_px.y;
    const float tan_half = std::tan(0.5f * camera.fov_y);
    const glm::vec3 direction =
        camera.forward() + camera.right() * (ndc_x * tan_half * aspect) + camera.up() * (ndc_y * tan_half);
    return {camera.eye(), glm::normalize(direction)};
}

glm::vec3 project(const OrbitCamera& camera, glm::vec3 point, glm::vec2 viewport_px) {
    const float aspect = viewport_px.x / std::max(viewport_px.y, 1.0f);
    const glm::vec4 clip = camera.projection(aspect) * camera.view() * glm::vec4(point, 1.0f);
    const glm::vec3 ndc = glm::vec3(clip) / clip.w;
    return {(ndc.x + 1.0f) * 0.5f * viewport_px.x, (1.0f - ndc.y) * 0.5f * viewport_px.y, ndc.z * 0.5f + 0.5f};
}

}  // namespace clothsim
