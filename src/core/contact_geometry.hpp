// Contact geometry shared by the two contact models (settings.hpp, ContactModel): where a particle closer
// than `thickness` to a collider surface touches it. The projection (colliders.cpp) moves the particle out
// by `depth` along `normal`; penalty contact (penalty_contact.cpp) pushes it with a force of the depth.
#pragma once

#include "clothsim/settings.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>

namespace clothsim {

// Where a particle touches a collider: the outward unit normal and how far to move along it. Written for a
// scalar type T; the state is double (state.hpp).
template <class T>
struct Contact {
    glm::vec<3, T> normal{T(0), T(1), T(0)};
    T depth = T(0);  // > 0 when the particle is closer than `thickness`
};

template <class T>
Contact<T> contact(const SphereCollider& sphere, glm::vec<3, T> p, T thickness) {
    const glm::vec<3, T> d = p - glm::vec<3, T>(sphere.center);
    Contact<T> c;
    const T reach = T(sphere.radius) + thickness;
    // Clearly outside (by a relative 1e-5, far beyond sqrt's rounding): no contact, no square root. The
    // depth says only what is known without it: at least at the shell (0).
    if (glm::dot(d, d) > reach * reach * T(1.00001)) {
        c.depth = T(0);
        return c;
    }
    const T length = glm::length(d);
    // A particle exactly at the centre has no direction: push it straight up.
    if (length > T(1e-12f)) c.normal = d / length;
    c.depth = reach - length;
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

}  // namespace clothsim
