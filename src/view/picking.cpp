#include "picking.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace clothsim {

std::optional<std::size_t> pick_particle(const Ray& ray, std::span<const glm::vec3> positions, float spread) {
    // The candidates: in front of the eye and inside the cone. The nearest of them to the eye marks the
    // surface the user sees; the ones within a slab behind it (ten cone radii deep, the depth a surface seen
    // at up to ~84 degrees spans inside the cone) are that visible surface, and of those the one nearest the
    // ray on screen (smallest angle off the ray) is the one under the cursor. A layer farther behind is
    // hidden by the visible one.
    const float spread2 = spread * spread;
    float front = INFINITY;
    for (const glm::vec3& p : positions) {
        const glm::vec3 to = p - ray.origin;
        const float depth = glm::dot(to, ray.direction);
        if (depth <= 0.0f) continue;
        const float off2 = glm::dot(to, to) - depth * depth;  // squared distance from the ray
        if (off2 <= spread2 * depth * depth) front = std::min(front, depth);
    }
    if (!std::isfinite(front)) return std::nullopt;
    const float back = front + 10.0f * spread * front;
    std::optional<std::size_t> best;
    float best_angle2 = INFINITY;
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const glm::vec3 to = positions[i] - ray.origin;
        const float depth = glm::dot(to, ray.direction);
        if (depth <= 0.0f || depth > back) continue;
        const float off2 = std::max(glm::dot(to, to) - depth * depth, 0.0f);
        if (off2 > spread2 * depth * depth) continue;
        const float angle2 = off2 / (depth * depth);
        if (angle2 < best_angle2) {
            best_angle2 = angle2;
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
