// Broad phase of the collision stage: axis-aligned boxes around blocks of consecutive particles (a grid row
// in the fast solver, kBlockParticles otherwise), and conservative tests of whether a collider can touch
// anything in a box. A collider is then tested particle by particle only on the blocks it may touch; a
// collider out of reach of every block costs one box test per block.
//
// The tests are conservative: every particle whose contact depth (colliders.hpp) is positive lies in a box
// the test accepts (they allow a relative margin of 1e-5 for rounding), so culling never changes a result.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include <glm/vec3.hpp>

#include <cmath>
#include <cstddef>

namespace clothsim {

inline constexpr std::size_t kBlockParticles = 64;  // block size when the particles are not a grid

struct Box {
    glm::vec3 lo{INFINITY};
    glm::vec3 hi{-INFINITY};
    bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
};

// The box around particles [begin, end); NaN coordinates are left out (a NaN particle touches nothing).
Box particle_bounds(const Vec3Array& position, std::size_t begin, std::size_t end);

// Whether a particle in `box` can come closer than `thickness` to the collider's surface.
bool may_touch(const SphereCollider& sphere, float thickness, const Box& box);
bool may_touch(const CubeCollider& cube, float thickness, const Box& box);
bool may_touch(const GroundCollider& ground, float thickness, const Box& box);

}  // namespace clothsim
