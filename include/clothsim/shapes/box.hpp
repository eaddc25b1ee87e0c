// A solid axis-aligned box (a "cube" in the first scene-file form).
#pragma once

#include "clothsim/shapes/shape.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <array>
#include <optional>
#include <utility>

namespace clothsim {

struct BoxCollider {
    glm::vec3 center{0.0f, 0.4f, 0.0f};  // m
    glm::vec3 size{0.5f, 0.5f, 0.5f};    // m: edge lengths along x, y, z
    bool operator==(const BoxCollider&) const = default;

    static constexpr std::string_view kName = "box";
    static constexpr std::string_view kHelp = "a solid axis-aligned box";
    static constexpr bool kHalfSpace = false;
    static constexpr float kFriction = 0.3f;
    static constexpr std::array<ShapeField<BoxCollider>, 2> fields() {
        // A function: its body sees the whole struct (clang rejects the members in a static initializer).
        return {{
            {"center", "m", -kShapeReach, kShapeReach, "box centre", [](BoxCollider& s) -> ShapeValue { return &s.center; }},
            {"size", "m", 0, kShapeReach, "box edge lengths along x, y, z", [](BoxCollider& s) -> ShapeValue { return &s.size; }},
        }};
    }
};

template <class T>
Contact<T> contact(const BoxCollider& box, glm::vec<3, T> p, T thickness) {
    using Vec = glm::vec<3, T>;
    const Vec local = p - Vec(box.center);
    const Vec q = glm::abs(local) - T(0.5) * Vec(box.size);  // per-axis distance outside a face
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

namespace box_detail {
// Slab test against the box grown by `grow`: the entry t and the axis it enters through (-1: starts inside).
template <class T>
std::optional<std::pair<T, int>> enter(const BoxCollider& box, glm::vec<3, T> p0, glm::vec<3, T> d, T grow) {
    T near = T(0), far = T(1);
    int axis = -1;
    for (int a = 0; a < 3; ++a) {
        const T lo = T(box.center[a]) - T(0.5) * T(box.size[a]) - grow;
        const T hi = T(box.center[a]) + T(0.5) * T(box.size[a]) + grow;
        if (d[a] == T(0)) {
            if (p0[a] < lo || p0[a] > hi) return std::nullopt;
            continue;
        }
        T t0 = (lo - p0[a]) / d[a], t1 = (hi - p0[a]) / d[a];
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > near) {
            near = t0;
            axis = a;
        }
        far = std::min(far, t1);
        if (!(near <= far)) return std::nullopt;
    }
    return std::pair<T, int>(near, axis);
}
}  // namespace box_detail

template <class T>
std::optional<SweptHit<T>> swept_hit(const BoxCollider& box, glm::vec<3, T> p0, glm::vec<3, T> p1, T thickness) {
    const glm::vec<3, T> d = p1 - p0;
    if (!box_detail::enter(box, p0, d, T(0))) return std::nullopt;
    const auto entry = box_detail::enter(box, p0, d, thickness);
    SweptHit<T> hit;
    if (!entry || entry->second < 0) return std::nullopt;  // started inside the shell: the depth test's case
    hit.t = entry->first;
    hit.normal = glm::vec<3, T>(T(0));
    hit.normal[entry->second] = d[entry->second] > T(0) ? T(-1) : T(1);
    return hit;
}

inline float signed_distance(const BoxCollider& box, glm::vec3 p) {
    const glm::vec3 q = glm::abs(p - box.center) - 0.5f * box.size;
    return glm::length(glm::max(q, glm::vec3(0.0f))) + std::min(std::max({q.x, q.y, q.z}), 0.0f);
}

inline bool may_touch(const BoxCollider& box, float thickness, const Box& cells) {
    using namespace shape_margin;
    if (cells.empty()) return false;
    const glm::vec3 half = 0.5f * box.size + thickness;
    const glm::vec3 grow(margin(2.0f * (largest(box.center) + largest(half) + largest(cells.lo) + largest(cells.hi))));
    const glm::vec3 lo = box.center - half - grow, hi = box.center + half + grow;
    return cells.lo.x < hi.x && cells.hi.x > lo.x && cells.lo.y < hi.y && cells.hi.y > lo.y && cells.lo.z < hi.z &&
           cells.hi.z > lo.z;
}

inline Box bounds(const BoxCollider& box) { return {box.center - 0.5f * box.size, box.center + 0.5f * box.size}; }

inline ShapeDrawing drawing(const BoxCollider& box) { return {UnitMesh::Cube, box.center, box.size}; }

}  // namespace clothsim
