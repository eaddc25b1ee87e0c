// A triangle mesh as the cloth (cloth.mesh = "skirt.obj"): its vertices are the particles, its rest shape the
// mesh as given (flat or not), placed like a mesh collider (scaled, turned, moved: ClothSettings).
//
// The model on a mesh, in the units of [material] (docs/MESH_CLOTH.md has the derivations and measurements):
//  - Stretch: a Hooke spring on every edge with van Gelder's stiffness (A. van Gelder, "Approximate simulation
//    of elastic membranes by triangulated spring meshes", J. Graphics Tools 3(2), 1998):
//    k_e = E sum_T A_T / |e|^2 over the one or two triangles T of edge e, E = E_u cos^2 + E_v sin^2 of the
//    edge's angle to u_axis. On equilateral triangles it is exact: an isotropic membrane of tensile stiffness E
//    and Poisson's ratio 1/3. On others it is not: a grid's right triangles come out 20% stiffer along their
//    legs, irregular Delaunay triangles 4-6% softer, and an anisotropic fabric's warp and weft are interpolated
//    (docs/MESH_CLOTH.md has the measurements).
//  - Shear: springs are a central-force lattice, whose shear stiffness follows its stretch (the Cauchy
//    relation: G = 3 E / 8 on equilateral triangles); material.shear has no element of its own on a mesh.
//  - Bending: a Hinge (spring.hpp) on every interior edge, Bergou et al. 2006's quadratic bending with
//    cotangent weights.
//  - Mass: each triangle's area times material.density, a third to each corner (per-spring form: cloth.mass
//    shared in proportion to those areas).
// In the per-spring form every edge is a spring of springs.structural (by the same cos^2 / sin^2 split) and
// every hinge has k = springs.bending.
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"
#include "clothsim/triangle_mesh.hpp"

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {

struct Scene;

// The cloth mesh's vertices placed in the world: scale, then turn (cloth.mesh_rotation, R = Rz Ry Rx as a
// mesh collider's), then move by cloth.origin.
std::vector<glm::dvec3> placed_cloth_vertices(const ClothSettings& cloth);

// Why `triangles` over `vertices` cannot be a cloth, or "" when they can: a vertex in no triangle, coordinates
// that are not finite, a degenerate triangle (a repeated vertex or no area), two vertices at one place (a seam
// that was not welded: the cloth would fall apart along it), an edge of more than two triangles, two triangles
// that run their shared edge the same way (faces not oriented alike), or a vertex where two sheets meet
// at a point only. The message names the vertex, triangle or edge (0-based indices, as pins use them).
std::string cloth_mesh_problem(const std::vector<glm::dvec3>& vertices,
                               const std::vector<std::array<std::uint32_t, 3>>& triangles);

// The springs, hinges and triangles of a mesh cloth whose rest shape is `rest` (topology.mesh is set; rows = 1,
// cols = the vertex count). With `stretch` (E_u, E_v): the material form (springs from membrane_springs, k = E_u w;
// hinges k = B w); without: the per-spring form (each edge a spring of springs.structural along the axis it is
// nearer, each hinge k = springs.bending). u_axis: the warp direction (normalised here).
// With membrane = Triangles (material form only) the stretch and shear are membrane_triangles' and the springs'
// weights are 0: they still measure strain, tear and carry the surface.
Topology mesh_topology(const std::vector<glm::dvec3>& rest, const std::vector<std::array<std::uint32_t, 3>>& triangles,
                       glm::dvec3 u_axis, std::optional<glm::dvec2> stretch,
                       MembraneModel membrane = MembraneModel::Springs);

// One spring per edge of the mesh, in the order mesh_topology lists them, van Gelder's for the membrane of tensile
// stiffness stretch = (E_u, E_v); weight = k / E_u (kind
// Structural, axis U), so springs.structural.x = E_u gives each its k. A live change of the stretch puts new
// weights on the running cloth (MassSpring::set_spring_weights).
// With membrane = Triangles every weight is 0 (the triangles carry the membrane).
std::vector<Spring> membrane_springs(const std::vector<glm::dvec3>& rest,
                                     const std::vector<std::array<std::uint32_t, 3>>& triangles, glm::dvec3 u_axis,
                                     glm::dvec2 stretch, MembraneModel membrane = MembraneModel::Springs);

// A constant-strain membrane triangle (spring.hpp: Membrane) for each of `triangles`, in their order: its rest
// frame is u_axis projected on the triangle's plane (the warp) and the normal cross it (the weft).
std::vector<Membrane> membrane_triangles(const std::vector<glm::dvec3>& rest,
                                         const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                         glm::dvec3 u_axis);

// Each vertex's share of the area (m^2): a third of each triangle it is a corner of.
std::vector<double> vertex_areas(const std::vector<glm::dvec3>& rest,
                                 const std::vector<std::array<std::uint32_t, 3>>& triangles);

// The checks of validate() that a mesh cloth adds: its mesh is loaded and not too large, its pins name its
// vertices (no grid preset: a mesh has no rows). Throws SceneError.
void validate_mesh_cloth(const Scene& scene);

// Each particle's mass (kg) for a mesh cloth whose vertices carry `area` (vertex_areas): cloth.mass shared in
// proportion to area (the material form's cloth.mass is density x area: derive_springs). What the builder and a
// live change of the fabric (apply_fabric) both put on the cloth. Throws SceneError naming the vertex when one
// carries too little area for a mass in float.
std::vector<float> mesh_cloth_masses(const ClothSettings& cloth, const std::vector<double>& area);

// One line on a mesh cloth for --print-scene and the panel: "mesh: 1024 vertices, 2945 edges (124 on the
// boundary), 1922 triangles; shortest edge 0.0323 m; critical substep 0.161 ms" (the explicit stability limit,
// stability.hpp; 0 or infinity leaves it out). From the running topology: after a tear, what is left.
std::string cloth_mesh_summary(const Topology& topology, std::size_t particles, double critical_substep);

}  // namespace clothsim
