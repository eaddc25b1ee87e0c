// A solid cylinder with a vertical axis, such as the support disc of the Cusick drape tester (ISO 9073-9,
// BS 5058: an 18 cm disc). Its flat top is at center.y + height / 2, its flat bottom at center.y - height / 2.
#pragma once

#include "clothsim/shapes/shape.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <array>
#include <optional>
#include <utility>

namespace clothsim {

struct CylinderCollider {
    glm::vec3 center{0.0f, 0.25f, 0.0f};  // m: the middle of the axis
    float radius = 0.09f;                 // m
    float height = 0.5f;                  // m: from the bottom face to the top face
    bool operator==(const CylinderCollider&) const = default;

    static constexpr std::string_view kName = "cylinder";
    static constexpr std::string_view kHelp = "a solid cylinder, axis along y (e.g. a Cusick drape tester's support disc)";
    static constexpr bool kHalfSpace = false;
    static constexpr float kFriction = 0.3f;
    static constexpr std::array<ShapeField<CylinderCollider>, 3> fields() {
        // A function: its body sees the whole struct (clang rejects the members in a static initializer).
        return {{
            {"center", "m", -kShapeReach, kShapeReach, "cylinder centre: the middle of its axis (top face at y + height / 2)", [](CylinderCollider& s) -> ShapeValue { return &s.center; }},
            {"radius", "m", 0, kShapeReach, "cylinder radius (a Cusick support disc: 0.09)", [](CylinderCollider& s) -> ShapeValue { return &s.radius; }},
            {"height", "m", 0, kShapeReach, "cylinder height, bottom face to top face", [](CylinderCollider& s) -> ShapeValue { return &s.height; }},
        }};
    }
};

// The nearest point of the solid lies on the top or bottom face, on the side, or on a rim (the circle where a
// face meets the side). Outside, the offset to it has a radial part (how far beyond the side) and a vertical
// part (how far beyond the face), either of which may be 0; at a rim both are positive and the normal points
// from the rim to the particle, as for a rounded edge (the capped cylinder's distance, Quilez, "Distance
// functions", iquilezles.org/articles/distfunctions). Inside, the way out is through the nearer of the face and
// the side.
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

namespace cylinder_detail {
// The segment p0 -> p0 + d (p0 relative to the centre) against the cylinder grown by `grow` (radius + grow,
// each face moved out by grow: flat, like the box's): the entry t and the surface it enters through, 0 a face,
// 1 the side, -1 none (it starts inside). The intersection of the slab between the faces with the infinite
// cylinder around the axis, each an interval of t.
template <class T>
std::optional<std::pair<T, int>> enter(const CylinderCollider& cylinder, glm::vec<3, T> p0, glm::vec<3, T> d, T grow) {
    T near = T(0), far = T(1);
    int surface = -1;
    const T half = T(0.5) * T(cylinder.height) + grow;
    if (d.y == T(0)) {
        if (std::abs(p0.y) > half) return std::nullopt;
    } else {
        T t0 = (-half - p0.y) / d.y, t1 = (half - p0.y) / d.y;
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > near) {
            near = t0;
            surface = 0;
        }
        far = std::min(far, t1);
    }
    const T radius = T(cylinder.radius) + grow;
    const T a = d.x * d.x + d.z * d.z;
    const T c = p0.x * p0.x + p0.z * p0.z - radius * radius;
    if (!(a > T(0))) {
        if (c > T(0)) return std::nullopt;  // moving along the axis, beside the cylinder
    } else {
        const T b = p0.x * d.x + p0.z * d.z;
        const T disc = b * b - a * c;
        if (!(disc >= T(0))) return std::nullopt;
        const T root = std::sqrt(disc);
        const T t0 = (-b - root) / a, t1 = (-b + root) / a;
        if (t0 > near) {
            near = t0;
            surface = 1;
        }
        far = std::min(far, t1);
    }
    if (!(near <= far)) return std::nullopt;
    return std::pair<T, int>(near, surface);
}
}  // namespace cylinder_detail

template <class T>
std::optional<SweptHit<T>> swept_hit(const CylinderCollider& cylinder, glm::vec<3, T> p0, glm::vec<3, T> p1,
                                     T thickness) {
    using Vec = glm::vec<3, T>;
    const Vec f = p0 - Vec(cylinder.center), d = p1 - p0;
    if (!cylinder_detail::enter(cylinder, f, d, T(0))) return std::nullopt;
    const auto entry = cylinder_detail::enter(cylinder, f, d, thickness);
    if (!entry) return std::nullopt;
    SweptHit<T> hit;
    if (entry->second < 0) {
        // Starts inside the flat-grown cylinder but outside the shell (the caller checked): beside a rim,
        // where the shell is rounded. It stops where it is, its motion toward the rim removed.
        hit.t = T(0);
        hit.normal = contact(cylinder, p0, thickness).normal;
        return hit;
    }
    hit.t = entry->first;
    if (entry->second == 0) {
        hit.normal = Vec(T(0), d.y > T(0) ? T(-1) : T(1), T(0));
    } else {
        const Vec at = f + hit.t * d;
        const T r = std::sqrt(at.x * at.x + at.z * at.z);
        hit.normal = r > T(1e-12f) ? Vec(at.x / r, T(0), at.z / r) : Vec(T(1), T(0), T(0));
    }
    return hit;
}

inline float signed_distance(const CylinderCollider& cylinder, glm::vec3 p) {
    const glm::vec3 local = p - cylinder.center;
    const glm::vec2 q(std::sqrt(local.x * local.x + local.z * local.z) - cylinder.radius,
                      std::abs(local.y) - 0.5f * cylinder.height);
    return glm::length(glm::max(q, glm::vec2(0.0f))) + std::min(std::max(q.x, q.y), 0.0f);
}

inline bool may_touch(const CylinderCollider& cylinder, float thickness, const Box& box) {
    using namespace shape_margin;
    if (box.empty()) return false;
    // Along the axis: the slab between the faces, each moved out by the thickness, meets the box's y range.
    const float half = 0.5f * cylinder.height + thickness;
    const float grow_y = margin(std::abs(cylinder.center.y) + half + std::abs(box.lo.y) + std::abs(box.hi.y));
    if (!(box.lo.y < cylinder.center.y + half + grow_y && box.hi.y > cylinder.center.y - half - grow_y)) return false;
    // Across it: the box's x-z rectangle comes within radius + thickness of the axis (the sphere's test in 2D).
    const glm::vec2 axis(cylinder.center.x, cylinder.center.z);
    const glm::vec2 nearest = glm::clamp(axis, glm::vec2(box.lo.x, box.lo.z), glm::vec2(box.hi.x, box.hi.z));
    const glm::vec2 d = axis - nearest;
    const float reach = cylinder.radius + thickness;
    const float scale = std::max({std::abs(axis.x), std::abs(axis.y), std::abs(nearest.x), std::abs(nearest.y)});
    const float grown = reach + margin(reach + 4.0f * scale);
    return glm::dot(d, d) < grown * grown;
}

inline Box bounds(const CylinderCollider& cylinder) {
    const glm::vec3 half(cylinder.radius, 0.5f * cylinder.height, cylinder.radius);
    return {cylinder.center - half, cylinder.center + half};
}

inline ShapeDrawing drawing(const CylinderCollider& cylinder) {
    return {UnitMesh::Cylinder, cylinder.center, glm::vec3(cylinder.radius, cylinder.height, cylinder.radius)};
}

}  // namespace clothsim
