// A solid sphere.
#pragma once

#include "clothsim/shapes/shape.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <array>
#include <optional>

namespace clothsim {

struct SphereCollider {
    glm::vec3 center{0.0f, 0.5f, 0.0f};  // m
    float radius = 0.3f;                 // m
    bool operator==(const SphereCollider&) const = default;

    static constexpr std::string_view kName = "sphere";
    static constexpr std::string_view kHelp = "a solid sphere";
    static constexpr bool kHalfSpace = false;
    static constexpr float kFriction = 0.3f;
    static constexpr std::array<ShapeField<SphereCollider>, 2> fields() {
        // A function: its body sees the whole struct (clang rejects the members in a static initializer).
        return {{
            {"center", "m", -kShapeReach, kShapeReach, "sphere centre", [](SphereCollider& s) -> ShapeValue { return &s.center; }},
            {"radius", "m", 0, kShapeReach, "sphere radius", [](SphereCollider& s) -> ShapeValue { return &s.radius; }},
        }};
    }
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

namespace sphere_detail {
// Smallest t in [0, 1] with |f + t d| = radius, if the segment reaches that sphere.
template <class T>
std::optional<T> enter(glm::vec<3, T> f, glm::vec<3, T> d, T radius) {
    const T a = glm::dot(d, d);
    if (!(a > T(0))) return std::nullopt;
    const T b = glm::dot(f, d);
    const T disc = b * b - a * (glm::dot(f, f) - radius * radius);
    if (!(disc >= T(0))) return std::nullopt;
    const T t = (-b - std::sqrt(disc)) / a;
    if (!(t <= T(1)) || (-b + std::sqrt(disc)) / a < T(0)) return std::nullopt;
    return std::max(t, T(0));
}
}  // namespace sphere_detail

template <class T>
std::optional<SweptHit<T>> swept_hit(const SphereCollider& sphere, glm::vec<3, T> p0, glm::vec<3, T> p1, T thickness) {
    const glm::vec<3, T> f = p0 - glm::vec<3, T>(sphere.center), d = p1 - p0;
    if (!sphere_detail::enter(f, d, T(sphere.radius))) return std::nullopt;
    SweptHit<T> hit;
    hit.t = sphere_detail::enter(f, d, T(sphere.radius) + thickness).value_or(T(0));
    const glm::vec<3, T> at = f + hit.t * d;
    const T length = glm::length(at);
    if (length > T(1e-12f)) hit.normal = at / length;
    return hit;
}

inline float signed_distance(const SphereCollider& sphere, glm::vec3 p) {
    return glm::length(p - sphere.center) - sphere.radius;
}

inline bool may_touch(const SphereCollider& sphere, float thickness, const Box& box) {
    using namespace shape_margin;
    if (box.empty()) return false;
    const glm::vec3 nearest = glm::clamp(sphere.center, box.lo, box.hi);
    const glm::vec3 d = sphere.center - nearest;
    const float reach = sphere.radius + thickness;
    // |v| <= 2 x largest component for a 3-vector: a cheap stand-in for the lengths in the rounding margin.
    const float grown = reach + margin(reach + 2.0f * (largest(sphere.center) + largest(nearest)));
    return glm::dot(d, d) < grown * grown;
}

inline Box bounds(const SphereCollider& sphere) {
    return {sphere.center - glm::vec3(sphere.radius), sphere.center + glm::vec3(sphere.radius)};
}

inline ShapeDrawing drawing(const SphereCollider& sphere) {
    return {UnitMesh::Sphere, sphere.center, glm::vec3(sphere.radius)};
}

}  // namespace clothsim
