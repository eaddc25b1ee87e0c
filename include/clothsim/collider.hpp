// The objects a cloth collides with: a list of shapes, any number of each kind. Each kind lives in its own
// header in shapes/ (shape.hpp says what one provides); this file registers them, in ColliderShape.
//
// Adding a kind: write shapes/<kind>.hpp (parameters, field rows, contact, swept_hit, signed_distance,
// may_touch, bounds, drawing), add it to ColliderShape below, and test it (tests/core/test_colliders.cpp).
// The collision stage, penalty contact, the broad phase, the scene file, --set, the panel and the renderer
// read every kind through this list (docs/ARCHITECTURE.md).
#pragma once

#include "clothsim/shapes/box.hpp"
#include "clothsim/shapes/cylinder.hpp"
#include "clothsim/shapes/mesh.hpp"
#include "clothsim/shapes/plane.hpp"
#include "clothsim/shapes/sphere.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace clothsim {

// The registered kinds; a scene file's `kind` names one of them (each kind's kName).
using ColliderShape = std::variant<SphereCollider, BoxCollider, CylinderCollider, PlaneCollider, MeshCollider>;
inline constexpr std::size_t kColliderKindCount = std::variant_size_v<ColliderShape>;

// How a kinematic collider moves (collider_motion.hpp): its shape's fields are its pose at time 0, and it moves
// at `velocity` and turns at `spin` from there, whatever the cloth does.
inline constexpr double kMaxColliderSpeed = 100.0;  // m/s: the largest velocity component a scene gives
inline constexpr double kMaxColliderSpin = 3600.0;  // degrees/s: ten turns a second
struct ColliderMotion {
    glm::vec3 velocity{0.0f};  // m/s
    glm::vec3 spin{0.0f};      // degrees/s: the rates of the rotation angles about x, y and z (R = Rz Ry Rx)
    double stop = INFINITY;    // s: the time it stops where it has got to (a drag's move: MassSpring::move_collider)
    bool moves() const { return velocity != glm::vec3(0.0f) || spin != glm::vec3(0.0f); }
    bool operator==(const ColliderMotion&) const = default;
};

// One object: its shape, its friction, whether it collides now (the panel switches one off without losing it)
// and how it moves.
struct Collider {
    ColliderShape shape;
    float friction = 0.3f;  // Coulomb coefficient (0 = frictionless)
    bool enabled = true;
    ColliderMotion motion;
    bool operator==(const Collider&) const = default;
    template <class Shape>
    static Collider of(Shape shape, bool enabled = true) {
        return Collider{shape, Shape::kFriction, enabled, {}};
    }
    std::size_t kind() const { return shape.index(); }
};

// The kinds' names in registration order ("sphere", "box", "cylinder", "plane", "mesh").
constexpr std::array<std::string_view, kColliderKindCount> collider_kind_names() {
    return []<std::size_t... I>(std::index_sequence<I...>) {
        return std::array<std::string_view, kColliderKindCount>{std::variant_alternative_t<I, ColliderShape>::kName...};
    }(std::make_index_sequence<kColliderKindCount>());
}
// A collider of kind `kind` (an index of ColliderShape) with its defaults.
inline Collider default_collider(std::size_t kind) {
    return [&]<std::size_t... I>(std::index_sequence<I...>) {
        Collider c;
        ((kind == I ? (void)(c = Collider::of(std::variant_alternative_t<I, ColliderShape>{})) : void()), ...);
        return c;
    }(std::make_index_sequence<kColliderKindCount>());
}
inline std::string_view kind_name(const Collider& c) { return collider_kind_names()[c.kind()]; }

// Whether the shape is a half-space (shape.hpp: kHalfSpace): it needs no swept test and only lowest points.
inline bool is_half_space(const Collider& c) {
    return std::visit([](const auto& s) { return std::decay_t<decltype(s)>::kHalfSpace; }, c.shape);
}

inline float signed_distance(const Collider& c, glm::vec3 p) {
    return std::visit([&](const auto& s) { return signed_distance(s, p); }, c.shape);
}
inline bool may_touch(const Collider& c, float thickness, const Box& box) {
    return std::visit([&](const auto& s) { return may_touch(s, thickness, box); }, c.shape);
}
inline ShapeDrawing drawing(const Collider& c) {
    return std::visit([](const auto& s) { return drawing(s); }, c.shape);
}
inline Box bounds(const Collider& c) {
    return std::visit([](const auto& s) { return bounds(s); }, c.shape);
}

// Where the segment from -> to first enters the solid, as a fraction of the way, if it does (the swept test
// of the contact with no thickness): what the app's alt+drag picks an object by. A half-space (the ground)
// is never picked.
inline std::optional<double> segment_entry(const Collider& c, glm::dvec3 from, glm::dvec3 to) {
    if (is_half_space(c)) return std::nullopt;
    return std::visit(
        [&](const auto& s) -> std::optional<double> {
            const auto hit = swept_hit(placed(s, 0.0f), from, to, 0.0);
            if (!hit) return std::nullopt;
            return hit->t;
        },
        c.shape);
}

}  // namespace clothsim
