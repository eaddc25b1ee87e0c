// A triangle mesh as a collider sees it: vertices and triangles in the mesh's own coordinates, and a
// bounding-volume hierarchy over the triangles for the three questions contact asks (shapes/mesh.hpp):
//  - nearest: the closest surface point within a radius, and on which side of the surface the point lies, by
//    the angle-weighted pseudonormal of the face, edge or vertex that point is on (Baerentzen & Aanaes, "Signed
//    distance computation using the angle weighted pseudonormal", IEEE TVCG 11(3), 2005): exact for a closed,
//    consistently oriented mesh;
//  - first_crossing: the first triangle a straight path crosses (Moeller & Trumbore, "Fast, minimum storage
//    ray-triangle intersection", 1997), for continuous collision;
//  - may_touch: whether any triangle's box meets a box, for the broad phase's block culling.
// Contact asks `nearest` within the thickness for every particle near the mesh in every substep: for that,
// a contact grid (a uniform grid of cells, each listing the triangles within `band` of it: the narrow band of
// a distance grid, with the exact triangles instead of sampled distances) answers with one cell's few
// triangles instead of a walk down the tree; the same answer, about 4x sooner over a table top (docs/COLLIDERS.md).
// The hierarchy is built once (top-down, split at the median centroid along the box's longest axis; Ericson,
// "Real-Time Collision Detection", 2005, ch. 6) and never changes: a moving collider moves the query into the
// mesh's coordinates instead. Immutable after construction, so colliders share one mesh (std::shared_ptr).
#pragma once

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

namespace clothsim {

// The most triangles a mesh may have (docs/SCENE_FILES.md): 2 million, 40 times the largest bundled mesh; the
// hierarchy and normals then take about 400 MB.
inline constexpr std::size_t kMaxMeshTriangles = 2'000'000;
// The largest coordinate magnitude a mesh may have, in its own units: a million (a kilometre in millimetres).
inline constexpr double kMaxMeshCoordinate = 1e6;

// Cells of edge `cell` from `origin`, `size` of them per axis; cell (i, j, k)'s triangles are
// triangles[start[c] .. start[c + 1]) with c = i + size.x (j + size.y k), in increasing index. A triangle is
// listed in every cell that its box grown by `band` meets, so every triangle within `band` of a point in a
// cell is in that cell's list.
//
// A cell that lists no triangle lies wholly farther than `band` from the surface, so wholly inside or wholly
// outside; for a closed mesh `inside` says which (1: inside the solid), found once per region of such cells
// that touch face to face (a flood fill, one signed nearest-point query at a cell's centre per region). A
// mesh that jumps onto the cloth finds the particles it swallowed by it (colliders.hpp: push_out_of_mesh),
// where the nearest-point test within the band sees nothing.
struct ContactGrid {
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    double band = 0.0, cell = 0.0;
    glm::dvec3 origin{0.0};
    std::array<int, 3> size{0, 0, 0};
    std::vector<std::uint32_t> start, triangles;
    std::vector<std::uint8_t> inside;  // per cell; empty for an open mesh

    // The index of the cell holding p, or kNone outside the grid (or for a NaN).
    std::size_t cell_of(glm::dvec3 p) const {
        std::size_t index = 0, stride = 1;
        for (int a = 0; a < 3; ++a) {
            const double at = std::floor((p[a] - origin[a]) / cell);
            if (!(at >= 0.0 && at < size[a])) return kNone;
            index += static_cast<std::size_t>(at) * stride;
            stride *= static_cast<std::size_t>(size[a]);
        }
        return index;
    }
    // Whether p lies inside a closed mesh and farther than `band` from its surface (by its cell: exact).
    bool deep_inside(glm::dvec3 p) const {
        if (inside.empty()) return false;
        const std::size_t c = cell_of(p);
        return c != kNone && inside[c] != 0;
    }
};

// The point of triangle abc nearest p (Ericson, "Real-Time Collision Detection", 2005, 5.1.5): what every
// nearest-point query of a mesh computes for each triangle it cannot pass over.
glm::dvec3 closest_point_on_triangle(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c);

class TriangleMesh {
public:
    using Triangle = std::array<std::uint32_t, 3>;  // vertex indices, counter-clockwise seen from outside

    // Throws std::invalid_argument naming the problem: no triangles, more than kMaxMeshTriangles, an index out
    // of range, a coordinate that is not finite or beyond kMaxMeshCoordinate.
    TriangleMesh(std::vector<glm::dvec3> vertices, std::vector<Triangle> triangles);

    const std::vector<glm::dvec3>& vertices() const { return vertices_; }
    const std::vector<Triangle>& triangles() const { return triangles_; }
    // The unit outward normal of each triangle (0 for a degenerate one), and each vertex's angle-weighted one.
    const std::vector<glm::dvec3>& face_normals() const { return face_normals_; }
    const std::vector<glm::dvec3>& vertex_normals() const { return vertex_normals_; }
    glm::dvec3 lo() const { return nodes_.front().lo; }
    glm::dvec3 hi() const { return nodes_.front().hi; }
    // Every edge is shared by exactly two triangles that run it in opposite directions: the mesh bounds a solid.
    bool closed() const { return closed_; }
    std::size_t node_count() const { return nodes_.size(); }

    struct Nearest {
        glm::dvec3 point;    // on the surface
        double distance;     // |p - point|
        glm::dvec3 normal;   // the unit pseudonormal at `point`
        bool inside;         // p lies behind the surface there: (p - point) . normal < 0
        std::uint32_t triangle;
    };
    // The surface point nearest p among those within `radius` of it (none: nothing that close).
    std::optional<Nearest> nearest(glm::dvec3 p, double radius) const;
    // The same by `grid` (this mesh's contact_grid for a band of at least `radius`).
    std::optional<Nearest> nearest(glm::dvec3 p, double radius, const ContactGrid& grid) const;
    // The contact grid for `band` (> 0), made at the first call for it and kept with the last few others.
    std::shared_ptr<const ContactGrid> contact_grid(double band) const;

    struct Crossing {
        double t;            // the path p0 + t (p1 - p0) meets the triangle at t in [0, 1]
        glm::dvec3 normal;   // the triangle's unit outward normal
        std::uint32_t triangle;
    };
    // The first triangle the path p0 -> p1 crosses; with `front_only`, only a crossing from its outside in.
    std::optional<Crossing> first_crossing(glm::dvec3 p0, glm::dvec3 p1, bool front_only) const;

    // Whether some triangle's box meets the box [lo, hi] (conservative: a box test, not the triangle).
    bool may_touch(glm::dvec3 lo, glm::dvec3 hi) const;

    // The generalised winding number at p (Jacobson, Kavan & Sorkine-Hornung, "Robust inside-outside
    // segmentation using generalized winding numbers", SIGGRAPH 2013): the solid angle of every triangle over
    // 4 pi; 1 inside a closed outward-oriented mesh, 0 outside. Costs every triangle: for tests and analyses.
    double winding_number(glm::dvec3 p) const;

private:
    struct Node {
        glm::dvec3 lo, hi;
        std::uint32_t first;  // leaf: its triangles are order_[first, first + count); inner: the right child
        std::uint32_t count;  // 0 for an inner node, whose left child follows it
    };
    // The node of order_[first, first + count), split at the median of the triangles' centres.
    std::uint32_t build(std::uint32_t first, std::uint32_t count, const std::vector<glm::dvec3>& centres);
    bool closest_of(glm::dvec3 p, std::uint32_t t, double& best2, bool found, Nearest& out) const;
    // Fills grid.inside (ContactGrid).
    void classify_empty_cells(ContactGrid& grid) const;

    std::vector<glm::dvec3> vertices_;
    std::vector<Triangle> triangles_;
    std::vector<glm::dvec3> face_normals_, vertex_normals_;
    // Each triangle's centroid and the distance from it to its farthest corner: |p - centre| - radius bounds
    // the distance from p to the triangle from below (closest_of's second cheap rejection).
    std::vector<glm::dvec4> spheres_;
    std::vector<std::array<glm::dvec3, 3>> edge_normals_;  // per triangle, edge k = (v_k, v_k+1): unit pseudonormal
    std::vector<std::uint32_t> order_;                     // triangle indices, in leaf order
    std::vector<Node> nodes_;                              // depth first; nodes_[0] is the root
    bool closed_ = false;
    struct Grids {
        std::mutex mutex;
        std::vector<std::shared_ptr<const ContactGrid>> recent;  // the most recent last
    };
    std::unique_ptr<Grids> grids_ = std::make_unique<Grids>();  // a memo: the mesh stays immutable
};

}  // namespace clothsim
