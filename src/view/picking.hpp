// Picking a cloth particle under the cursor and dragging it: ray maths only, no OpenGL.
#pragma once

#include "camera.hpp"

#include <glm/vec3.hpp>

#include <cstddef>
#include <optional>
#include <span>

namespace clothsim {

// The particle under the cursor: among the particles in front of the ray origin whose distance from the
// ray is at most `spread` times their depth along it (a cone, so the tolerance is the same number of pixels
// near and far: spread = pixels * 2 tan(fov_y / 2) / viewport height), those on the visible surface (within
// a slab behind the nearest one), and of those the nearest the ray on screen.
std::optional<std::size_t> pick_particle(const Ray& ray, std::span<const glm::vec3> positions, float spread);

// `spread` for a tolerance of `pixels` on screen.
float pick_spread(const OrbitCamera& camera, float pixels, float viewport_height_px);

// Where the ray meets the plane through `point` with normal `normal`; nullopt when parallel or behind.
std::optional<glm::vec3> intersect_plane(const Ray& ray, glm::vec3 point, glm::vec3 normal);

}  // namespace clothsim
