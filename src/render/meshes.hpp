// Geometry of the static shapes (sphere, cube, cylinder, ground, a mesh collider's triangles), built on the CPU
// and uploaded once.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

namespace clothsim {

struct MeshData {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> uvs;
    std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from outside
};

// Unit sphere (radius 1) as a latitude/longitude mesh of `stacks` x `slices` quads.
MeshData make_uv_sphere(int stacks, int slices);
// Unit cube (edge 1, centred on the origin), 4 vertices per face so each face has its own normal and UVs.
MeshData make_cube();
// Closed unit cylinder (radius 1, height 1, axis along y, centred on the origin) of `slices` side quads: the
// side with radial normals and two flat caps with their own vertices and normals (+y on top, -y below), so
// the rim is a sharp edge. Scaled by (radius, height, radius) it is the cylinder collider.
MeshData make_cylinder(int slices);
// A square in the y = 0 plane, `half_size` metres from the centre to each edge, facing +y.
MeshData make_ground(float half_size);
// A mesh collider's triangles (clothsim/triangle_mesh.hpp), three vertices each: smooth (the mesh's
// angle-weighted vertex normal) where that normal is within 30 degrees of the face's, flat across sharper edges.
class TriangleMesh;
MeshData make_collider_mesh(const TriangleMesh& mesh);

}  // namespace clothsim
