// Geometry of the static shapes (sphere, cube, ground), built on the CPU and uploaded once.
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
// A square in the y = 0 plane, `half_size` metres from the centre to each edge, facing +y.
MeshData make_ground(float half_size);

}  // namespace clothsim
