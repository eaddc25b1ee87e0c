// Per-vertex normals of the cloth for rendering: the area-weighted mean of the adjacent triangles' normals
// (each triangle adds its un-normalised cross product, whose length is twice its area).
#pragma once

#include "clothsim/state.hpp"

#include <glm/vec3.hpp>

#include <vector>

namespace clothsim {

// Resizes `normals` to the particle count. A grid whose triangles are Topology::cell_triangles is swept by
// rows of cells (vectorised with the fast solver's kernel, FastSolver::kernel; threaded from 128 x 128 on)
// with the same sums in the same order as the triangle list, so both give the same bits. A particle in no triangle (a 1 x N chain) gets u x v of nothing:
// (0, 1, 0), so the renderer never normalises a zero vector.
void compute_vertex_normals(const Topology& topology, const DVec3Array& position, std::vector<glm::vec3>& normals);

}  // namespace clothsim
