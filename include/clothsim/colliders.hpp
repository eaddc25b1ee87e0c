// Collision with a sphere, an axis-aligned box and the ground plane.
//
// After integration every free particle closer than `thickness` to a collider surface is projected out
// to that distance along the surface normal (the box: along the shortest way out). The contact is
// inelastic: the inward part of the substep's motion is removed, and the push itself adds no velocity.
// Friction acts on the tangential motion like Coulomb friction in position-based dynamics (Mueller et
// al. 2007, Macklin et al. 2014): it is reduced by at most mu times the normal correction, and stops
// when it is smaller (static friction). A particle resting on a plane is pushed
// back by g h^2 each substep, so its sliding velocity drops by mu g h per substep: deceleration mu g.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include <glm/vec3.hpp>

namespace clothsim {

// Signed distance from p to the collider surface (m): negative inside.
float signed_distance(const SphereCollider& sphere, glm::vec3 p);
float signed_distance(const CubeCollider& cube, glm::vec3 p);
float signed_distance(const GroundCollider& ground, glm::vec3 p);

// Collision stages for particles [begin, end) (all by default). Pinned particles are never moved.
inline constexpr std::size_t kAllParticles = static_cast<std::size_t>(-1);
void collide(State& state, const SphereCollider& sphere, float thickness, std::size_t begin = 0,
             std::size_t end = kAllParticles);
void collide(State& state, const CubeCollider& cube, float thickness, std::size_t begin = 0,
             std::size_t end = kAllParticles);
void collide(State& state, const GroundCollider& ground, float thickness, std::size_t begin = 0,
             std::size_t end = kAllParticles);
// Every enabled collider, in the order sphere, cube, ground. For float (the simulation) and double (the
// reference solution).
template <class T>
void collide_all(BasicState<T>& state, const ColliderSettings& colliders, std::size_t begin = 0,
                 std::size_t end = kAllParticles);

}  // namespace clothsim
