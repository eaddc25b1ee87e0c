#include "clothsim/colliders.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace clothsim {
namespace {

// Where a particle touches a collider: the outward unit normal and how far to move along it.
struct Contact {
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
    float depth = 0.0f;  // > 0 when the particle is closer than `thickness`
};

Contact contact(const SphereCollider& sphere, glm::vec3 p, float thickness) {
    const glm::vec3 d = p - sphere.center;
    const float length = glm::length(d);
    Contact c;
    // A particle exactly at the centre has no direction: push it straight up.
    if (length > 1e-12f) c.normal = d / length;
    c.depth = sphere.radius + thickness - length;
    return c;
}

Contact contact(const CubeCollider& cube, glm::vec3 p, float thickness) {
    const glm::vec3 local = p - cube.center;
    const glm::vec3 q = glm::abs(local) - 0.5f * cube.size;  // per-axis distance outside a face
    const glm::vec3 side(local.x < 0.0f ? -1.0f : 1.0f, local.y < 0.0f ? -1.0f : 1.0f,
                         local.z < 0.0f ? -1.0f : 1.0f);
    Contact c;
    const float q_max = std::max({q.x, q.y, q.z});
    if (q_max <= 0.0f) {
        // Inside or on the surface: leave through the nearest face (the axis with the largest q).
        const int axis = q.x == q_max ? 0 : (q.y == q_max ? 1 : 2);
        c.normal = glm::vec3(0.0f);
        c.normal[axis] = side[axis];
        c.depth = thickness - q_max;
        return c;
    }
    const glm::vec3 outside = glm::max(q, glm::vec3(0.0f)) * side;
    const float distance = glm::length(outside);
    c.normal = outside / distance;
    c.depth = thickness - distance;
    return c;
}

Contact contact(const GroundCollider& ground, glm::vec3 p, float thickness) {
    return {glm::vec3(0.0f, 1.0f, 0.0f), ground.height + thickness - p.y};
}

// Cheap tests, written so the compiler vectorises them, of whether any particle of a range is close
// enough to need the full contact: most rows of a cloth touch nothing, and then cost one pass of compares.
bool any_near(const State& state, const SphereCollider& sphere, float thickness, std::size_t begin, std::size_t end) {
    const float reach = (sphere.radius + thickness) * (sphere.radius + thickness);
    bool any = false;
    for (std::size_t i = begin; i < end; ++i) {
        const float dx = state.position.x[i] - sphere.center.x, dy = state.position.y[i] - sphere.center.y,
                    dz = state.position.z[i] - sphere.center.z;
        any |= dx * dx + dy * dy + dz * dz < reach;
    }
    return any;
}
bool any_near(const State& state, const CubeCollider& cube, float thickness, std::size_t begin, std::size_t end) {
    const glm::vec3 lo = cube.center - 0.5f * cube.size - thickness, hi = cube.center + 0.5f * cube.size + thickness;
    bool any = false;
    for (std::size_t i = begin; i < end; ++i) {
        const float x = state.position.x[i], y = state.position.y[i], z = state.position.z[i];
        any |= (x > lo.x) & (x < hi.x) & (y > lo.y) & (y < hi.y) & (z > lo.z) & (z < hi.z);
    }
    return any;
}
bool any_near(const State& state, const GroundCollider& ground, float thickness, std::size_t begin, std::size_t end) {
    const float top = ground.height + thickness;
    bool any = false;
    for (std::size_t i = begin; i < end; ++i) any |= state.position.y[i] < top;
    return any;
}

template <class Shape>
void collide_shape(State& state, const Shape& shape, float friction, float thickness, std::size_t begin,
                   std::size_t end) {
    // NaN positions fail every compare above; they stay NaN either way (the guard reports them).
    if (!any_near(state, shape, thickness, begin, end)) return;
    for (std::size_t i = begin; i < end; ++i) {
        if (state.pinned[i]) continue;
        const Contact c = contact(shape, state.position.get(i), thickness);
        if (!(c.depth > 0.0f)) continue;
        const glm::vec3 motion = state.motion.get(i);
        const float normal_motion = glm::dot(motion, c.normal);
        const glm::vec3 tangential = motion - normal_motion * c.normal;
        // Coulomb: the tangential motion loses at most mu times the normal push (static when it is less).
        const float slide = glm::length(tangential);
        const glm::vec3 friction_cut =
            slide > 0.0f ? -tangential * (std::min(slide, friction * c.depth) / slide) : glm::vec3(0.0f);
        state.position.add(i, c.normal * c.depth + friction_cut);
        // Inelastic contact: the push moves the particle out but does not launch it. Keeping the push in
        // the motion (x_prev left in place, as plain Verlet projection does) turns a deep penetration into a
        // velocity of depth / h: a cloth started half inside the sphere exploded that way.
        state.motion.set(i, tangential + friction_cut + std::max(normal_motion, 0.0f) * c.normal);
    }
}

}  // namespace

float signed_distance(const SphereCollider& sphere, glm::vec3 p) {
    return glm::length(p - sphere.center) - sphere.radius;
}

float signed_distance(const CubeCollider& cube, glm::vec3 p) {
    const glm::vec3 q = glm::abs(p - cube.center) - 0.5f * cube.size;
    return glm::length(glm::max(q, glm::vec3(0.0f))) + std::min(std::max({q.x, q.y, q.z}), 0.0f);
}

float signed_distance(const GroundCollider& ground, glm::vec3 p) { return p.y - ground.height; }

void collide(State& state, const SphereCollider& sphere, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, sphere, sphere.friction, thickness, begin, std::min(end, state.size()));
}
void collide(State& state, const CubeCollider& cube, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, cube, cube.friction, thickness, begin, std::min(end, state.size()));
}
void collide(State& state, const GroundCollider& ground, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, ground, ground.friction, thickness, begin, std::min(end, state.size()));
}

void collide_all(State& state, const ColliderSettings& colliders, std::size_t begin, std::size_t end) {
    if (colliders.sphere.enabled) collide(state, colliders.sphere, colliders.thickness, begin, end);
    if (colliders.cube.enabled) collide(state, colliders.cube, colliders.thickness, begin, end);
    if (colliders.ground.enabled) collide(state, colliders.ground, colliders.thickness, begin, end);
}

}  // namespace clothsim
