#include "picking.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace clothsim {

std::optional<std::size_t> pick_particle(const Ray& ray, std::span<const glm::vec3> positions, float spread) {
    std::optional<std::size_t> best;
    float best_depth = INFINITY;
    const float spread2 = spread * spread;
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const glm::vec3 to = positions[i] - ray.origin;
        const float depth = glm::dot(to, ray.direction);
        if (depth <= 0.0f) continue;
        const float off2 = glm::dot(to, to) - depth * depth;  // squared distance from the ray
        if (off2 <= spread2 * depth * depth && depth < best_depth) {
            best_depth = depth;
            best = i;
        }
    }
    return best;
}

float pick_spread(const OrbitCamera& camera, float pixels, float viewport_height_px) {
    return pixels * 2.0f * std::tan(0.5f * camera.fov_y) / std::max(viewport_height_px, 1.0f);
}

std::optional<glm::vec3> intersect_plane(const Ray& ray, glm::vec3 point, glm::vec3 normal) {
    const float denom = glm::dot(ray.direction, normal);
    if (std::fabs(denom) < 1e-6f) return std::nullopt;
    const float t = glm::dot(point - ray.origin, normal) / denom;
    if (t < 0.0f) return std::nullopt;
    return ray.origin + t * ray.direction;
}

}  // namespace clothsim
