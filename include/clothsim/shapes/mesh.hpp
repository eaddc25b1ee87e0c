// A triangle mesh from an OBJ file (triangle_mesh.hpp), placed in the world: scaled by `scale`, turned by
// `rotation` (degrees about x, then y, then z, the axes fixed: R = Rz Ry Rx) and moved to `position`.
//
// Contact is the nearest surface point within the thickness (the mesh's hierarchy finds it); its side comes
// from the angle-weighted pseudonormal, so a closed mesh pushes a particle out the way it came in and an open
// one (a sheet) holds it on the side it is on. A particle deeper inside a closed mesh than the thickness is
// not seen by the proximity test: continuous collision keeps particles from getting there (a path that
// crosses the surface stops where it entered the shell), and a mesh that appears or jumps onto the cloth
// pushes out what it swallowed then (colliders.hpp: push_out_of_mesh).
// Queries run in the mesh's coordinates: the particle is moved into them (R^T (p - position) / scale) and
// the answer back. `placed()` computes R once per collision stage instead of per particle.
#pragma once

#include "clothsim/shapes/shape.hpp"
#include "clothsim/triangle_mesh.hpp"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <string>

namespace clothsim {

struct MeshCollider {
    std::string file;                          // an OBJ file (mesh_file.hpp: how it is found)
    glm::vec3 position{0.0f, 0.0f, 0.0f};      // m: where the mesh's origin goes
    glm::vec3 rotation{0.0f, 0.0f, 0.0f};      // degrees about x, then y, then z
    float scale = 1.0f;                        // mesh units to metres
    std::shared_ptr<const TriangleMesh> mesh;  // read from `file` when the scene is loaded; none: no contact
    bool operator==(const MeshCollider&) const = default;

    static constexpr std::string_view kName = "mesh";
    static constexpr std::string_view kHelp = "a triangle mesh from an OBJ file";
    static constexpr bool kHalfSpace = false;
    static constexpr float kFriction = 0.3f;
    static constexpr std::array<ShapeField<MeshCollider>, 4> fields() {
        return {{
            {"file", "", 0, 0, "OBJ file: beside the scene file, else a bundled mesh", [](MeshCollider& s) -> ShapeValue { return &s.file; }},
            {"position", "m", -kShapeReach, kShapeReach, "where the mesh's origin goes", [](MeshCollider& s) -> ShapeValue { return &s.position; }},
            {"rotation", "degrees", -360, 360, "turns about x, then y, then z", [](MeshCollider& s) -> ShapeValue { return &s.rotation; }},
            {"scale", "", 1e-6, kShapeReach, "mesh units to metres", [](MeshCollider& s) -> ShapeValue { return &s.scale; }},
        }};
    }
};

// R = Rz Ry Rx for `degrees` about x, y and z.
inline glm::dmat3 rotation_matrix(glm::dvec3 degrees) {
    const glm::dvec3 r = degrees * (std::numbers::pi / 180.0);
    const double cx = std::cos(r.x), sx = std::sin(r.x), cy = std::cos(r.y), sy = std::sin(r.y);
    const double cz = std::cos(r.z), sz = std::sin(r.z);
    const glm::dmat3 rx(1, 0, 0, 0, cx, sx, 0, -sx, cx);  // column-major
    const glm::dmat3 ry(cy, 0, -sy, 0, 1, 0, sy, 0, cy);
    const glm::dmat3 rz(cz, sz, 0, -sz, cz, 0, 0, 0, 1);
    return rz * ry * rx;
}

// A mesh collider with its rotation computed: what the collision stage queries, particle by particle.
struct PlacedMesh {
    const TriangleMesh* mesh = nullptr;
    glm::dmat3 rotation{1.0};
    glm::dvec3 position{0.0};
    double scale = 1.0;
    std::shared_ptr<const ContactGrid> grid;  // for the thickness it was placed with (none: the tree answers)

    glm::dvec3 to_mesh(glm::dvec3 p) const { return glm::transpose(rotation) * (p - position) / scale; }
    glm::dvec3 to_world(glm::dvec3 q) const { return rotation * (q * scale) + position; }
};

// A mesh may be thinner than the thickness: a path from the shell over one face can leave through the other.
constexpr bool sweeps_from_shell(const PlacedMesh&) { return true; }

// Placed for contact within `thickness` (0: no grid).
inline PlacedMesh placed(const MeshCollider& m, float thickness = 0.0f) {
    PlacedMesh at{m.mesh.get(), rotation_matrix(m.rotation), glm::dvec3(m.position), static_cast<double>(m.scale), nullptr};
    if (at.mesh && thickness > 0.0f && at.scale > 0.0) at.grid = at.mesh->contact_grid(static_cast<double>(thickness) / at.scale);
    return at;
}

template <class T>
Contact<T> contact(const PlacedMesh& m, glm::vec<3, T> p, T thickness) {
    Contact<T> c;
    if (!m.mesh || !(m.scale > 0.0)) return c;
    const double shell = static_cast<double>(thickness) / m.scale;
    const glm::dvec3 q = m.to_mesh(glm::dvec3(p));
    const auto near = m.grid && m.grid->band >= shell ? m.mesh->nearest(q, shell, *m.grid) : m.mesh->nearest(q, shell);
    if (!near) return c;
    // Outside: away from the surface point; inside (behind it): towards it. On the surface: the pseudonormal.
    glm::dvec3 normal = near->normal;
    if (near->distance > 1e-12) normal = (near->inside ? near->point - q : q - near->point) / near->distance;
    const double depth = near->inside ? shell + near->distance : shell - near->distance;
    c.normal = glm::vec<3, T>(m.rotation * normal);
    c.depth = static_cast<T>(depth * m.scale);
    return c;
}
template <class T>
Contact<T> contact(const MeshCollider& m, glm::vec<3, T> p, T thickness) {
    return contact(placed(m), p, thickness);
}

// The first crossing of the surface (of a closed mesh: from outside in; an open one: either side); `t` is
// backed off along the path to where it entered the thickness shell of that triangle's plane.
template <class T>
std::optional<SweptHit<T>> swept_hit(const PlacedMesh& m, glm::vec<3, T> p0, glm::vec<3, T> p1, T thickness) {
    if (!m.mesh || !(m.scale > 0.0)) return std::nullopt;
    const glm::dvec3 q0 = m.to_mesh(glm::dvec3(p0)), q1 = m.to_mesh(glm::dvec3(p1));
    const auto crossing = m.mesh->first_crossing(q0, q1, m.mesh->closed());
    if (!crossing) return std::nullopt;
    const glm::dvec3 d = q1 - q0;
    const double along = glm::dot(d, crossing->normal);  // < 0 from the outside in
    const double back = std::fabs(along) > 0.0 ? (static_cast<double>(thickness) / m.scale) / std::fabs(along) : 1.0;
    SweptHit<T> hit;
    hit.t = static_cast<T>(std::max(0.0, crossing->t - back));
    hit.normal = glm::vec<3, T>(m.rotation * (along > 0.0 ? -crossing->normal : crossing->normal));
    return hit;
}
template <class T>
std::optional<SweptHit<T>> swept_hit(const MeshCollider& m, glm::vec<3, T> p0, glm::vec<3, T> p1, T thickness) {
    return swept_hit(placed(m), p0, p1, thickness);
}

// Negative inside a closed mesh (by the pseudonormal at the nearest point); for an open mesh, behind it.
inline float signed_distance(const MeshCollider& m, glm::vec3 p) {
    if (!m.mesh) return INFINITY;
    const PlacedMesh at = placed(m);
    const auto near = at.mesh->nearest(at.to_mesh(glm::dvec3(p)), INFINITY);
    if (!near) return INFINITY;
    return static_cast<float>((near->inside ? -near->distance : near->distance) * at.scale);
}

// The box's corners in the mesh's coordinates, boxed again and grown by the thickness: conservative.
inline bool may_touch(const PlacedMesh& m, float thickness, const Box& box) {
    using namespace shape_margin;
    if (box.empty() || !m.mesh) return false;
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 corner((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z);
        const glm::dvec3 q = m.to_mesh(corner);
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    }
    const double grow = (static_cast<double>(thickness) + margin(2.0f * (largest(box.lo) + largest(box.hi)))) / m.scale;
    return m.mesh->may_touch(lo - glm::dvec3(grow), hi + glm::dvec3(grow));
}
inline bool may_touch(const MeshCollider& m, float thickness, const Box& box) {
    return may_touch(placed(m), thickness, box);
}

inline Box bounds(const MeshCollider& m) {
    if (!m.mesh) return Box{glm::vec3(m.position), glm::vec3(m.position)};
    const PlacedMesh at = placed(m);
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    const glm::dvec3 mlo = m.mesh->lo(), mhi = m.mesh->hi();
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 corner((k & 1) ? mhi.x : mlo.x, (k & 2) ? mhi.y : mlo.y, (k & 4) ? mhi.z : mlo.z);
        const glm::dvec3 w = at.to_world(corner);
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
    }
    return Box{glm::vec3(lo), glm::vec3(hi)};
}

inline ShapeDrawing drawing(const MeshCollider& m) {
    return {UnitMesh::Mesh, m.position, glm::vec3(m.scale), m.rotation, m.mesh.get()};
}

}  // namespace clothsim
