// Kinematic colliders: where a moving collider is at a time, and how its surface moves over a substep.
//
// A collider's shape fields are its pose at time 0; with a ColliderMotion (collider.hpp) it moves at
// `velocity` (m/s) and its rotation angles change at `spin` (degrees/s about x, y and z, R = Rz Ry Rx, the
// convention of a mesh's `rotation`), whatever the cloth does: a scripted motion, as Blender's animated
// collision objects and Houdini Vellum's animated colliders are. The turn is about the shape's centre (a
// mesh: its `position`, where its origin goes). A spin about one axis is a constant angular velocity; spins
// about several are rates of the three angles, as a keyframed Euler rotation is.
//
// Which turns change the geometry: a mesh turns; a sphere and a vertical cylinder about y are unchanged by
// theirs, which only move their surface (a spinning ball drags the cloth by friction); a box stays axis-aligned
// and a plane horizontal, so a spin that would tilt them is refused (spin_problem). A plane's velocity along
// x and z moves its surface only (a conveyor belt). A drag's move (MassSpring::move_collider) also sets the
// motion's `stop`: the time it stops where it has got to.
//
// The contact (colliders.hpp) uses the motion relative to the surface: a particle's displacement over the
// substep less the displacement of the collider's material point where it is (SurfaceMotion), for the
// friction and for the continuous test, which sweeps the relative path against the pose at the substep's end
// (exact for a translation; for a turn, the path in the collider's frame is taken as straight). The contact
// then gives the particle the surface's displacement plus what is left of its relative motion.
#pragma once

#include "clothsim/collider.hpp"
#include "clothsim/settings.hpp"

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>

namespace clothsim {

// Whether an enabled collider of the list moves (then the cloth never sleeps: something drives it).
inline bool colliders_move(const ColliderSettings& colliders) {
    return std::any_of(colliders.shapes.begin(), colliders.shapes.end(),
                       [](const Collider& c) { return c.enabled && c.motion.moves(); });
}

// The centre a collider turns about, in its pose at time 0.
inline glm::dvec3 pivot(const Collider& c) {
    return std::visit(
        [](const auto& s) -> glm::dvec3 {
            using Shape = std::decay_t<decltype(s)>;
            if constexpr (std::is_same_v<Shape, MeshCollider>) {
                return glm::dvec3(s.position);
            } else if constexpr (std::is_same_v<Shape, PlaneCollider>) {
                return glm::dvec3(0.0, s.height, 0.0);
            } else {
                return glm::dvec3(s.center);
            }
        },
        c.shape);
}

// The collider's orientation at time t: a mesh's rotation plus its spin's turn; the other kinds have no
// rotation field, only the spin's.
inline glm::dmat3 orientation(const Collider& c, double t) {
    const glm::dvec3 spun = glm::dvec3(c.motion.spin) * t;
    if (const auto* mesh = std::get_if<MeshCollider>(&c.shape)) return rotation_matrix(glm::dvec3(mesh->rotation) + spun);
    return rotation_matrix(spun);
}

// Writes into `out` (a copy of `base`, of the same kind) the pose of `base` at time t. Only the pose's fields
// are written, so updating a copy each substep allocates nothing.
inline void pose_at(const Collider& base, double t, Collider& out) {
    t = std::min(t, base.motion.stop);
    const glm::dvec3 moved = glm::dvec3(base.motion.velocity) * t;
    std::visit(
        [&](auto& s) {
            using Shape = std::decay_t<decltype(s)>;
            const Shape& from = std::get<Shape>(base.shape);
            if constexpr (std::is_same_v<Shape, MeshCollider>) {
                s.position = glm::vec3(glm::dvec3(from.position) + moved);
                s.rotation = glm::vec3(glm::dvec3(from.rotation) + glm::dvec3(base.motion.spin) * t);
            } else if constexpr (std::is_same_v<Shape, PlaneCollider>) {
                s.height = static_cast<float>(double(from.height) + moved.y);
            } else {
                s.center = glm::vec3(glm::dvec3(from.center) + moved);
            }
        },
        out.shape);
}

// How the collider's surface moves over a substep [t0, t1]: the displacement of its material point that is
// at p at t1. That point was at pivot(t0) + R(t0) R(t1)^T (p - pivot(t1)) at t0.
// `reach` bounds that displacement wherever the solid is: |v| h, plus the turn's angle (at most the sum of the
// three angles' changes: each factor of Rz Ry Rx turns a point by at most its own angle) times the farthest
// corner of the solid's box from the pivot, which bounds every point of the solid in any pose. The broad phase
// reaches that much farther for a moving collider (colliders.hpp). A half-space's is |v| h: its test reads
// only the particles' lowest points.
struct SurfaceMotion {
    glm::dvec3 pivot_start{0.0}, pivot_end{0.0};
    glm::dmat3 back{1.0};  // R(t0) R(t1)^T
    double reach = 0.0;    // m
    glm::dvec3 displacement(glm::dvec3 p) const { return p - (pivot_start + back * (p - pivot_end)); }
};
inline SurfaceMotion surface_motion(const Collider& c, double t0, double t1) {
    t0 = std::min(t0, c.motion.stop);
    t1 = std::min(t1, c.motion.stop);
    const glm::dvec3 p0 = pivot(c), v(c.motion.velocity);
    const glm::dvec3 w(c.motion.spin);
    SurfaceMotion m;
    m.pivot_start = p0 + v * t0;
    m.pivot_end = p0 + v * t1;
    const double h = std::abs(t1 - t0);
    m.reach = glm::length(v) * h;
    if (w != glm::dvec3(0.0)) {
        m.back = orientation(c, t0) * glm::transpose(orientation(c, t1));
        if (!is_half_space(c)) {
            const Box box = bounds(c);
            const glm::dvec3 far = glm::max(glm::abs(glm::dvec3(box.lo) - p0), glm::abs(glm::dvec3(box.hi) - p0));
            const double angle = (std::abs(w.x) + std::abs(w.y) + std::abs(w.z)) * h * (std::numbers::pi / 180.0);
            m.reach += angle * glm::length(far);
        }
    }
    m.reach = m.reach * (1.0 + 1e-6) + 1e-9;  // rounding room, as the shapes' margins
    return m;
}

// Moves a collider's pose (its centre; a mesh's position; a plane's height by by.y).
inline void translate(Collider& c, glm::dvec3 by) {
    std::visit(
        [&](auto& s) {
            using Shape = std::decay_t<decltype(s)>;
            if constexpr (std::is_same_v<Shape, MeshCollider>) {
                s.position = glm::vec3(glm::dvec3(s.position) + by);
            } else if constexpr (std::is_same_v<Shape, PlaneCollider>) {
                s.height = static_cast<float>(double(s.height) + by.y);
            } else {
                s.center = glm::vec3(glm::dvec3(s.center) + by);
            }
        },
        c.shape);
}

// The same collider with another velocity and stop time from time t on: the fields (its pose at time 0) are
// shifted so that its pose at t stays where `c` is then; its spin goes on.
inline Collider with_velocity(const Collider& c, double t, glm::vec3 velocity, double stop) {
    Collider now = c;
    pose_at(c, t, now);  // its pose at t, as fields
    now.motion = ColliderMotion{velocity, c.motion.spin, INFINITY};
    Collider out = now;
    pose_at(now, -t, out);  // back to time 0 along the new motion
    out.motion.stop = stop;
    return out;
}

// Why a collider's spin cannot be followed by its shape, or nothing: a box stays axis-aligned, a cylinder
// vertical and a plane horizontal.
inline std::optional<std::string> spin_problem(const Collider& c) {
    const glm::vec3 w = c.motion.spin;
    if (std::holds_alternative<BoxCollider>(c.shape) && w != glm::vec3(0.0f)) {
        return "a box stays axis-aligned; allowed: spin = [0, 0, 0] (a mesh collider of a box turns)";
    }
    if ((std::holds_alternative<CylinderCollider>(c.shape) || std::holds_alternative<PlaneCollider>(c.shape)) &&
        (w.x != 0.0f || w.z != 0.0f)) {
        return std::string(kind_name(c)) + " stays " +
               (std::holds_alternative<PlaneCollider>(c.shape) ? "horizontal" : "vertical") +
               "; allowed: a spin about y only, [0, w, 0]";
    }
    return std::nullopt;
}

}  // namespace clothsim
