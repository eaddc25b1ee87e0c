// A horizontal plane facing up, y = height: the ground, and the floor of any scene. Everything below it is
// solid (a half-space), so a path cannot pass through it unseen and it needs no swept test; a particle block
// meets it when the block's lowest point does.
#pragma once

#include "clothsim/shapes/shape.hpp"

#include <array>
#include <optional>

namespace clothsim {

struct PlaneCollider {
    float height = 0.0f;  // m: the plane y = height
    bool operator==(const PlaneCollider&) const = default;

    static constexpr std::string_view kName = "plane";
    static constexpr std::string_view kHelp = "the horizontal plane y = height, solid below (the ground)";
    static constexpr bool kHalfSpace = true;
    static constexpr float kFriction = 0.5f;
    static constexpr std::array<ShapeField<PlaneCollider>, 1> fields() {
        // A function: its body sees the whole struct (clang rejects the members in a static initializer).
        return {{
            {"height", "m", -kShapeReach, kShapeReach, "plane height", [](PlaneCollider& s) -> ShapeValue { return &s.height; }},
        }};
    }
};

template <class T>
Contact<T> contact(const PlaneCollider& plane, glm::vec<3, T> p, T thickness) {
    return {glm::vec<3, T>(T(0), T(1), T(0)), T(plane.height) + thickness - p.y};
}

template <class T>
std::optional<SweptHit<T>> swept_hit(const PlaneCollider&, glm::vec<3, T>, glm::vec<3, T>, T) {
    return std::nullopt;
}

inline float signed_distance(const PlaneCollider& plane, glm::vec3 p) { return p.y - plane.height; }

inline bool may_touch(const PlaneCollider& plane, float thickness, const Box& box) {
    using namespace shape_margin;
    if (box.empty()) return false;
    const float top = plane.height + thickness;
    return box.lo.y < top + margin(std::abs(top) + std::abs(box.lo.y));
}

// Unbounded sideways; only its height bounds anything.
inline Box bounds(const PlaneCollider& plane) {
    return {glm::vec3(INFINITY, plane.height, INFINITY), glm::vec3(-INFINITY, plane.height, -INFINITY)};
}

inline ShapeDrawing drawing(const PlaneCollider& plane) {
    return {UnitMesh::Plane, glm::vec3(0.0f, plane.height, 0.0f), glm::vec3(1.0f)};
}

}  // namespace clothsim
