// What every collider shape provides (one header per kind in this folder; collider.hpp registers them):
//
//   struct XCollider {                       the shape's parameters, with defaults
//       static constexpr std::string_view kName, kHelp;   its `kind` in scene files, one line for the panel
//       static constexpr bool kHalfSpace;    true when nothing can pass through it unseen (the plane): it needs
//                                            no swept test and reads only a block's lowest point
//       static constexpr float kFriction;    its default Coulomb coefficient
//       static constexpr std::array fields(); its field rows: name, unit, range, help, accessor
//   };
//   Contact<T> contact(const XCollider&, glm::vec<3, T> p, T thickness);      where p touches it (depth > 0)
//   std::optional<SweptHit<T>> swept_hit(const XCollider&, p0, p1, thickness); a path through the solid
//   float signed_distance(const XCollider&, glm::vec3 p);                      negative inside
//   bool may_touch(const XCollider&, float thickness, const Box& box);         conservative broad-phase test
//   Box bounds(const XCollider&);                                              the solid's box
//   ShapeDrawing drawing(const XCollider&);                                    a unit mesh and its placement
//   placed(const XCollider&, thickness) (optional): what the queries take, made once per collision stage
//   sweeps_from_shell(const placed form&) (optional): swept_hit also for paths that start in the shell
//
// The contact model is the same for every kind (colliders.hpp): the particle is moved out along `normal` by
// `depth`, with Coulomb friction; penalty contact pushes it with a force of the depth instead.
#pragma once

#include "clothsim/bounding_box.hpp"

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>
#include <variant>

namespace clothsim {

// Where a particle touches a collider: the outward unit normal and how far to move along it. Written for a
// scalar type T; the state is double (state.hpp).
template <class T>
struct Contact {
    glm::vec<3, T> normal{T(0), T(1), T(0)};
    T depth = T(0);  // > 0 when the particle is closer than `thickness`
};

// Continuous collision: where the straight path p0 -> p1 of a substep passed through the solid shape (not the
// thickness shell around it) although both ends are outside. A path that only grazes the shell (a particle
// sliding over the surface cuts a chord into it) is not a pass. `t` is where the path enters the shell and
// `normal` the shell's outward normal there.
template <class T>
struct SweptHit {
    T t = T(0);
    glm::vec<3, T> normal{T(0), T(1), T(0)};
};

// The unit meshes the renderer holds, and where one stands for a shape: scaled by `scale`, moved to `center`
// (the plane: a large floor at center.y).
// A mesh collider draws its own triangles (`triangles`), turned by `rotation` (degrees about x, y, z).
enum class UnitMesh { Sphere, Cube, Cylinder, Plane, Mesh };
class TriangleMesh;
struct ShapeDrawing {
    UnitMesh mesh;
    glm::vec3 center;
    glm::vec3 scale;
    glm::vec3 rotation{0.0f};
    const TriangleMesh* triangles = nullptr;
};

// What the collision stage queries, particle by particle: the shape itself, or (shapes/mesh.hpp) a form with
// what every query would compute again made once.
template <class Shape>
const Shape& placed(const Shape& shape, float /*thickness*/ = 0.0f) {
    return shape;
}
// Whether swept_hit may be asked for a path that starts in the thickness shell: a thin shape (a mesh) can be
// passed through from there in one substep; the analytic shapes leave that case to the depth test.
template <class Shape>
constexpr bool sweeps_from_shell(const Shape&) {
    return false;
}

// A field of a shape, as scene files, --set and the panel name it within its [[colliders.shapes]] entry.
using ShapeValue = std::variant<float*, glm::vec3*, std::string*>;
template <class Shape>
struct ShapeField {
    std::string_view name;
    std::string_view unit;
    double min, max;  // valid range (inclusive), per component for vectors
    std::string_view help;
    ShapeValue (*ref)(Shape&);
};

// Room for rounding in the broad-phase tests: a relative 1e-5 of the magnitudes involved (float's epsilon is
// 6e-8), so culling never changes a result (broad_phase.hpp).
namespace shape_margin {
inline float margin(float scale) { return 1e-5f * (1.0f + scale); }
inline float largest(glm::vec3 v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }
}  // namespace shape_margin

inline constexpr double kShapeReach = 1e4;  // m: the largest coordinate or size a shape field takes

}  // namespace clothsim
