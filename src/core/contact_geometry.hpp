// Contact geometry shared by the two contact models (settings.hpp, ContactModel): where a particle closer
// than `thickness` to a collider surface touches it. The projection (colliders.cpp) moves the particle out
// by `depth` along `normal`; penalty contact (penalty_contact.cpp) pushes it with a force of the depth.
#pragma once

#include "clothsim/settings.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>

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

// The solid cylinder with a vertical axis: the nearest point of the solid lies on the top or bottom face,
// on the side, or on a rim (the circle where a face meets the side). Outside, the offset to it has a radial
// part (how far beyond the side) and a vertical part (how far beyond the face), either of which may be 0; at
// a rim both are positive and the normal points from the rim to the particle, as for a rounded edge (the
// capped cylinder's distance, Quilez, "Distance functions", iquilezles.org/articles/distfunctions). Inside,
// the way out is through the nearer of the face and the side.
template <class T>
Contact<T> contact(const CylinderCollider& cylinder, glm::vec<3, T> p, T thickness) {
    using Vec = glm::vec<3, T>;
    const Vec local = p - Vec(cylinder.center);
    Contact<T> c;
    // Clearly outside the shell's own bounding cylinder (by a relative 1e-5, as for the sphere): no contact,
    // no square root. The depth says only what is known without it: at least at the shell (0).
    const T r2 = local.x * local.x + local.z * local.z;
    const T reach_r = T(cylinder.radius) + thickness, reach_y = T(0.5) * T(cylinder.height) + thickness;
    if (r2 > reach_r * reach_r * T(1.00001) || std::abs(local.y) > reach_y * T(1.00001)) {
        c.depth = T(0);
        return c;
    }
    const T r = std::sqrt(r2);
    // Outward from the axis; a particle on the axis has no direction: +x.
    const Vec radial = r > T(1e-12f) ? Vec(local.x / r, T(0), local.z / r) : Vec(T(1), T(0), T(0));
    const Vec vertical(T(0), local.y < T(0) ? T(-1) : T(1), T(0));  // toward the nearer face
    const T side = r - T(cylinder.radius);                            // > 0 beyond the side
    const T face = std::abs(local.y) - T(0.5) * T(cylinder.height);  // > 0 beyond the nearer face
    if (side > T(0) || face > T(0)) {
        const T s = std::max(side, T(0)), f = std::max(face, T(0));
        const T distance = s > T(0) && f > T(0) ? std::sqrt(s * s + f * f) : s + f;
        c.normal = (s * radial + f * vertical) / distance;
        c.depth = thickness - distance;
        return c;
    }
    // Inside or on the surface (a NaN position too: its depth is NaN and nothing moves it).
    if (face >= side) {
        c.normal = vertical;
        c.depth = thickness - face;
    } else {
        c.normal = radial;
        c.depth = thickness - side;
    }
    return c;
}

template <class T>
Contact<T> contact(const GroundCollider& ground, glm::vec<3, T> p, T thickness) {
    return {glm::vec<3, T>(T(0), T(1), T(0)), T(ground.height) + thickness - p.y};
}

}  // namespace clothsim
