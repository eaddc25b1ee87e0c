// Closed triangle meshes the project makes itself: the bundled objects (clothsim-make-meshes writes them to
// assets/meshes) and the meshes the tests and benchmarks compare with the analytic shapes. Every one is
// closed and oriented outward (TriangleMesh::closed, winding number 1 inside).
#pragma once

#include "clothsim/collider.hpp"
#include "clothsim/triangle_mesh.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <functional>
#include <optional>
#include <vector>

namespace clothsim {

// A sphere of `radius` about the origin: an icosahedron's faces split `subdivisions` times, each into four,
// the new vertices pushed onto the sphere: 20 x 4^subdivisions triangles (4: 5120, 6: 81920).
TriangleMesh icosphere(double radius, int subdivisions);

// An axis-aligned box of edge lengths `size` centred on the origin: two triangles per face.
TriangleMesh box_mesh(glm::dvec3 size);

// A surface of revolution about the y axis: the profile (radius, height) from a point on the axis to
// another, each point a ring of vertices (`slices` at the widest, fewer in proportion to the radius, 12 at
// least) zipped to the next, every face turned outward (away from the axis side of the profile). Closed when
// both ends lie on the axis.
TriangleMesh lathe(const std::vector<glm::dvec2>& profile, int slices);

// A round pedestal table (the `tablecloth` scene's): a top of radius 0.5 m, 0.76 m high and 6 cm thick, with
// a rim rounded to a radius of 3 cm, on a column and a round foot, standing on y = 0. One closed surface of
// revolution.
TriangleMesh round_table();

// The surface where `field` (negative inside) is zero, over the box [lo, hi] sampled every `cell` metres: marching
// tetrahedra (each grid cube split into the six tetrahedra of Kuhn's triangulation around its main diagonal,
// the same split in every cube, so neighbouring cubes share their faces' triangulations; Doi & Koide, IEICE
// Trans. E74(1), 1991). A vertex lies on a grid edge where the field changes sign, kept at least 2% of the edge
// from either end, and shared by every triangle on that edge: a field negative inside the box and positive on
// its boundary gives a closed, oriented (outward) surface. Written here, about eighty lines, instead of taking
// VTK, CGAL or OpenVDB (hundreds of megabytes of packages) for a tool that makes the bundled meshes once.
TriangleMesh isosurface(const std::function<double(glm::dvec3)>& field, glm::dvec3 lo, glm::dvec3 hi, double cell);

// A dress-form mannequin on a stand (the `mannequin-drape` scene's): hips, waist, chest and shoulders of
// ellipsoids and capsules blended smoothly (Quilez's polynomial smooth minimum), a neck, arms hanging at the
// sides, on a pole and a round base standing on y = 0; 1.6 m high, about 0.5 m across the shoulders and arms.
// One closed surface (isosurface, 1.6 cm cells: about 40,000 triangles).
TriangleMesh mannequin();

// A chair (the `chair-drape` scene's): a seat 0.45 m high and 0.44 m square, four legs, a backrest, its edges
// rounded to 1.5 cm (the legs 1 cm); one closed surface (isosurface, 1.5 cm cells: about 40,000 triangles).
TriangleMesh chair();

// A collider's surface as triangles in world coordinates (for `--obj-colliders`): a mesh as placed, a sphere as
// an icosphere of 1280 triangles, a box, a cylinder of 64 sides; none for a plane (it has no edge) or a kind
// without a surface here.
std::optional<TriangleMesh> collider_surface(const Collider& collider);

}  // namespace clothsim
