#include "clothsim/colliders.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace clothsim {
namespace {

// Where a particle touches a collider: the outward unit normal and how far to move along it. Templates on
// the scalar: float for the simulation, double for the reference solution.
template <class T>
struct Contact {
    glm::vec<3, T> normal{T(0), T(1), T(0)};
    T depth = T(0);  // > 0 when the particle is closer than `thickness`
};

template <class T>
Contact<T> contact(const SphereCollider& sphere, glm::vec<3, T> p, T thickness) {
    const glm::vec<3, T> d = p - glm::vec<3, T>(sphere.center);
    const T length = glm::length(d);
    Contact<T> c;
    // A particle exactly at the centre has no direction: push it straight up.
    if (length > T(1e-12f)) c.normal = d / length;
    c.depth = T(sphere.radius) + thickness - length;
    return c;
}

template <class T>
Contact<T> contact(const CubeCollider& cube, glm::vec<3, T> p, T thickness) {
    using Vec = glm::vec<3, T>;
    const Vec local = p - Vec(cube.center);
    const Vec q = glm::abs(local) - T(0.5) * Vec(cube.size);  // per-axis distance outside a face
    const Vec side(local.x < T(0) ? T(-1) : T(1), local.y < T(0) ? T(-1) : T(1), local.z < T(0) ? T(-1) : T(1));
    Contact<T> c;
    const T q_max = std::max({q.x, q.y, q.z});
    if (q_max <= T(0)) {
        // Inside or on the surface: leave through the nearest face (the axis with the largest q).
        const int axis = q.x == q_max ? 0 : (q.y == q_max ? 1 : 2);
        c.normal = Vec(T(0));
        c.normal[axis] = side[axis];
        c.depth = thickness - q_max;
        return c;
    }
    const Vec outside = glm::max(q, Vec(T(0))) * side;
    const T distance = glm::length(outside);
    c.normal = outside / distance;
    c.depth = thickness - distance;
    return c;
}

template <class T>
Contact<T> contact(const GroundCollider& ground, glm::vec<3, T> p, T thickness) {
    return {glm::vec<3, T>(T(0), T(1), T(0)), T(ground.height) + thickness - p.y};
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

template <class T, class Shape>
void collide_shape(BasicState<T>& state, const Shape& shape, T friction, T thickness, std::size_t begin,
                   std::size_t end) {
    using Vec = glm::vec<3, T>;
    // NaN positions fail every compare in any_near; they stay NaN either way (the guard reports them).
    if constexpr (std::is_same_v<T, float>) {
        if (!any_near(state, shape, thickness, begin, end)) return;
    }
    for (std::size_t i = begin; i < end; ++i) {
        if (state.pinned[i]) continue;
        const Contact<T> c = contact(shape, state.position.get(i), thickness);
        if (!(c.depth > T(0))) continue;
        const Vec motion = state.motion.get(i);
        const T normal_motion = glm::dot(motion, c.normal);
        const Vec tangential = motion - normal_motion * c.normal;
        // Coulomb: the tangential motion loses at most mu times the normal push (static when it is less).
        const T slide = glm::length(tangential);
        const Vec friction_cut = slide > T(0) ? -tangential * (std::min(slide, friction * c.depth) / slide) : Vec(T(0));
        state.position.add(i, c.normal * c.depth + friction_cut);
        // Inelastic contact: the push moves the particle out but does not launch it. Keeping the push in
        // the motion (x_prev left in place, as plain Verlet projection does) turns a deep penetration into a
        // velocity of depth / h: a cloth started half inside the sphere exploded that way.
        state.motion.set(i, tangential + friction_cut + std::max(normal_motion, T(0)) * c.normal);
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

template <class T>
void collide_all(BasicState<T>& state, const ColliderSettings& colliders, std::size_t begin, std::size_t end) {
    end = std::min(end, state.size());
    const T thickness = colliders.thickness;
    if (colliders.sphere.enabled) collide_shape(state, colliders.sphere, T(colliders.sphere.friction), thickness, begin, end);
    if (colliders.cube.enabled) collide_shape(state, colliders.cube, T(colliders.cube.friction), thickness, begin, end);
    if (colliders.ground.enabled) collide_shape(state, colliders.ground, T(colliders.ground.friction), thickness, begin, end);
}
template void collide_all<float>(State&, const ColliderSettings&, std::size_t, std::size_t);
template void collide_all<double>(DState&, const ColliderSettings&, std::size_t, std::size_t);

void collide(State& state, const SphereCollider& sphere, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, sphere, sphere.friction, thickness, begin, std::min(end, state.size()));
}
void collide(State& state, const CubeCollider& cube, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, cube, cube.friction, thickness, begin, std::min(end, state.size()));
}
void collide(State& state, const GroundCollider& ground, float thickness, std::size_t begin, std::size_t end) {
    collide_shape(state, ground, ground.friction, thickness, begin, std::min(end, state.size()));
}


}  // namespace clothsim
