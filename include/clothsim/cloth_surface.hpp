// The cloth's surface as drawn and exported once it has torn: the mesh split along the tear.
//
// Each particle stands for the patch of cloth around it, half a cell in every direction. An untorn cell is
// drawn as its two triangles (Topology::triangles). A torn cell, one built whole that lost a triangle to a
// broken spring (tearing.hpp), is drawn instead as four quadrants, one per corner particle: the particle, the
// points of the two cell edges it lies on, and the cell's centre. Where an edge's spring holds, its point is the
// edge's middle, shared by both ends. Where it broke, each end has a point of its own (the vertex is split):
// the end's half of the edge. It continues the end's own row or column beyond it, towards p + (p - back) / 2,
// while that still points across the edge, else it points at the other end; it reaches no further than half
// the rest length nor halfway to the other end, so the sides never overlap. Corners of the cell
// still joined by a spring of the cell (structural or shear) share one centre, the mean of their quadrants'
// parallelogram corners e_1 + e_2 - p; the pieces of a cell have one each. So a cut through a flat cloth
// shows a clean seam where the two sides meet, a tear that opens shows a crack as wide as the pieces have
// parted beyond their rest, and no triangle spans a broken spring. The particles keep their indices (first);
// the split vertices follow them. Edge points on an edge of two torn cells are shared by both.
// A mesh cloth (cloth.mesh) splits the same way with its triangles as the cells: a torn triangle, one it had
// when built that lost an edge's spring, is drawn as three corner quadrilaterals (the corner, its two edges'
// points and the piece's centre, the mean over the piece's corners of (2 e_1 + 2 e_2 - p) / 3: the triangle's
// centroid while its edges hold, so the six triangles tile it); a broken edge's end points at the other end.
#pragma once

#include "clothsim/state.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace clothsim {

struct ClothSurface {
    // The point of a cell edge from particle `from` towards particle `to`: the middle when the spring
    // between them holds (`whole`), else the end's own half (`back` is the particle before `from` on the
    // same row or column when the spring to it holds, else kNoParticle; `half_rest` is half the rest length).
    struct EdgePoint {
        std::uint32_t from = 0, to = 0, back = 0;
        float half_rest = 0.0f;
        bool whole = false;
    };
    // The centre of one piece of a torn cell: the mean over its corners of e_1 + e_2 - p on a grid, of
    // (2 e_1 + 2 e_2 - p) / 3 on a mesh cloth's triangle (vertex indices).
    struct Centre {
        std::array<std::array<std::uint32_t, 3>, 4> corner{};  // {p, e_1, e_2}
        int count = 0;
    };
    static constexpr std::uint32_t kNoParticle = 0xffffffffu;

    std::size_t particles = 0;
    // Empty while no cell is torn (draw Topology::triangles then); else every triangle to draw, counter-clockwise
    // seen from u_axis x v_axis as the topology's, over particles + edge_points + centres vertices.
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<EdgePoint> edge_points;  // vertices particles .. particles + edge_points.size() - 1
    std::vector<Centre> centres;         // then these
    // Each split vertex's place, for its UV: (column, row) on a grid (grid_uv); its texture coordinate (m, as
    // Topology::uv) on a mesh cloth.
    std::vector<glm::vec2> split_place;
    bool mesh = false;  // the cells are a mesh cloth's triangles

    bool split() const { return !triangles.empty(); }
    std::size_t vertex_count() const { return particles + edge_points.size() + centres.size(); }
};

// The cells a tear can leave torn, taken when the cloth is built.
struct ClothCells {
    // A grid: per cell (row-major, (rows - 1) x (cols - 1)), 1 where the topology has both the builder's
    // triangles of the cell, (00, 01, 10) and (01, 11, 10). Empty otherwise.
    std::vector<std::uint8_t> whole;
    // A mesh cloth: its triangles as built. Empty otherwise.
    std::vector<std::array<std::uint32_t, 3>> triangles;
};
ClothCells cells_at_start(const Topology& topology, std::size_t particles);

// The surface of `topology`: the cells of `at_start` (cells_at_start) that have lost a triangle are split. Any
// other topology, or one with no torn cell, gives an unsplit surface. `rest` holds the rest positions the rest
// lengths come from.
ClothSurface build_cloth_surface(const Topology& topology, const DVec3Array& rest, const ClothCells& at_start);

// The texture coordinate of a place on the grid, (column, row): u from 0 at column 0 to 1 at the last, v from 1
// at row 0 to 0 at the last. Particles and a grid's split vertices (ClothSurface::split_place) alike.
glm::vec2 grid_uv(const Topology& topology, glm::vec2 grid);

// Resizes `vertices`, which holds the particles' positions, to surface.vertex_count() and writes the split
// vertices' positions after them.
void place_split_vertices(const ClothSurface& surface, std::vector<glm::vec3>& vertices);

// Area-weighted vertex normals of the split surface (as compute_vertex_normals, normals.hpp: a vertex in no
// triangle gets (0, 1, 0)).
void split_surface_normals(const ClothSurface& surface, const std::vector<glm::vec3>& vertices,
                           std::vector<glm::vec3>& normals);

}  // namespace clothsim
