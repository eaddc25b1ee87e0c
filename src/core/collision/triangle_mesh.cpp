#include "clothsim/triangle_mesh.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace clothsim {
namespace {

constexpr std::uint32_t kLeafTriangles = 4;

// Where on a triangle its closest point lies: the face, a vertex (0, 1, 2) or an edge (k: from vertex k to k + 1).
enum class Feature { Face, Vertex, Edge };
struct Closest {
    glm::dvec3 point;
    Feature feature;
    int index;  // the vertex or edge
};

// The point of the three edges of abc closest to p: what is left of a triangle without area.
Closest closest_on_edges(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const glm::dvec3 corner[3] = {a, b, c};
    Closest best{a, Feature::Vertex, 0};
    double best2 = INFINITY;
    for (int k = 0; k < 3; ++k) {
        const glm::dvec3 from = corner[k], along = corner[(k + 1) % 3] - from;
        const double length2 = glm::dot(along, along);
        const double t = length2 > 0.0 ? std::clamp(glm::dot(p - from, along) / length2, 0.0, 1.0) : 0.0;
        const glm::dvec3 q = from + t * along;
        const double d2 = glm::dot(p - q, p - q);
        if (d2 < best2) {
            best2 = d2;
            best = t <= 0.0 ? Closest{from, Feature::Vertex, k}
                   : t >= 1.0 ? Closest{corner[(k + 1) % 3], Feature::Vertex, (k + 1) % 3}
                              : Closest{q, Feature::Edge, k};
        }
    }
    return best;
}

// The point of triangle abc closest to p (Ericson, "Real-Time Collision Detection", 2005, 5.1.5), by the Voronoi
// region p lies in.
Closest closest_on_triangle(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    // Without area (coincident or collinear corners) the regions below divide by zero, and on a needle (a width
    // under 1e-12 of its longest edge, as a triangle with one edge of 1e-22 m and two of 2 m) their differences
    // cancel to noise and pick the wrong region, a point off the triangle: the edges instead, which lie within
    // that width of every point of it.
    const glm::dvec3 normal = glm::cross(ab, ac), bc = c - b;
    const double longest = std::max({glm::dot(ab, ab), glm::dot(ac, ac), glm::dot(bc, bc)});
    if (!(glm::dot(normal, normal) > 1e-24 * longest * longest)) return closest_on_edges(p, a, b, c);
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return {a, Feature::Vertex, 0};
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return {b, Feature::Vertex, 1};
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return {a + (d1 / (d1 - d3)) * ab, Feature::Edge, 0};
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return {c, Feature::Vertex, 2};
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return {a + (d2 / (d2 - d6)) * ac, Feature::Edge, 2};
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        return {b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b), Feature::Edge, 1};
    }
    const double denom = va + vb + vc;
    const double v = vb / denom, w = vc / denom;
    return {a + ab * v + ac * w, Feature::Face, 0};
}

[[gnu::always_inline]] inline double box_distance2(glm::dvec3 p, glm::dvec3 lo, glm::dvec3 hi) {
    const double x = std::max({lo.x - p.x, p.x - hi.x, 0.0});
    const double y = std::max({lo.y - p.y, p.y - hi.y, 0.0});
    const double z = std::max({lo.z - p.z, p.z - hi.z, 0.0});
    return x * x + y * y + z * z;
}

// The segment p0 + t d, t in [t_lo, t_hi], meets the box (slab test).
bool segment_meets_box(glm::dvec3 p0, glm::dvec3 d, double t_hi, glm::dvec3 lo, glm::dvec3 hi) {
    double near = 0.0, far = t_hi;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) {
            if (p0[a] < lo[a] || p0[a] > hi[a]) return false;
            continue;
        }
        double t0 = (lo[a] - p0[a]) / d[a], t1 = (hi[a] - p0[a]) / d[a];
        if (t0 > t1) std::swap(t0, t1);
        near = std::max(near, t0);
        far = std::min(far, t1);
        if (near > far) return false;
    }
    return true;
}

}  // namespace

glm::dvec3 closest_point_on_triangle(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    return closest_on_triangle(p, a, b, c).point;
}

TriangleMesh::TriangleMesh(std::vector<glm::dvec3> vertices, std::vector<Triangle> triangles)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)) {
    if (triangles_.empty()) throw std::invalid_argument("the mesh has no triangles");
    if (triangles_.size() > kMaxMeshTriangles) {
        throw std::invalid_argument("the mesh has " + std::to_string(triangles_.size()) + " triangles; at most " +
                                    std::to_string(kMaxMeshTriangles) + " are allowed");
    }
    for (std::size_t i = 0; i < vertices_.size(); ++i) {
        const glm::dvec3 v = vertices_[i];
        if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
            throw std::invalid_argument("vertex " + std::to_string(i + 1) + " has a coordinate that is not a finite number");
        }
        if (std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) > kMaxMeshCoordinate) {
            throw std::invalid_argument("vertex " + std::to_string(i + 1) + " has a coordinate beyond 1e6; allowed: within +-1e6");
        }
    }
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        for (std::uint32_t v : triangles_[t]) {
            if (v >= vertices_.size()) {
                throw std::invalid_argument("triangle " + std::to_string(t + 1) + " names vertex " + std::to_string(v + 1) +
                                            "; the mesh has " + std::to_string(vertices_.size()));
            }
        }
    }
    // Normals: each face's; each vertex's weighted by the face's angle there; each edge's the sum of its faces'
    // (Baerentzen & Aanaes 2005).
    const std::size_t n = triangles_.size();
    face_normals_.resize(n);
    spheres_.resize(n);
    vertex_normals_.assign(vertices_.size(), glm::dvec3(0.0));
    for (std::size_t t = 0; t < n; ++t) {
        const Triangle& tri = triangles_[t];
        const glm::dvec3 a = vertices_[tri[0]], b = vertices_[tri[1]], c = vertices_[tri[2]];
        const glm::dvec3 cross = glm::cross(b - a, c - a);
        const double length = glm::length(cross);
        const glm::dvec3 normal = length > 0.0 ? cross / length : glm::dvec3(0.0);
        face_normals_[t] = normal;
        const glm::dvec3 centre = (a + b + c) / 3.0;
        spheres_[t] = glm::dvec4(centre, std::max({glm::length(a - centre), glm::length(b - centre), glm::length(c - centre)}));
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 p = vertices_[tri[k]];
            const glm::dvec3 e1 = vertices_[tri[(k + 1) % 3]] - p, e2 = vertices_[tri[(k + 2) % 3]] - p;
            const double l1 = glm::length(e1), l2 = glm::length(e2);
            const double angle = l1 > 0.0 && l2 > 0.0 ? std::acos(std::clamp(glm::dot(e1, e2) / (l1 * l2), -1.0, 1.0)) : 0.0;
            vertex_normals_[tri[k]] += angle * normal;
        }
    }
    for (glm::dvec3& v : vertex_normals_) {
        const double length = glm::length(v);
        v = length > 0.0 ? v / length : glm::dvec3(0.0);
    }
    // The edges: each triangle side (t, k) from tri[k] to tri[k + 1], listed under its lower vertex and sorted
    // there by its upper vertex, then by 3 t + k, so the sides of one edge are neighbours and their faces'
    // normals are summed in triangle order. The mesh is closed when every edge has one side each way.
    const std::size_t sides = 3 * n;
    std::vector<std::uint32_t> first_side(vertices_.size() + 1, 0);
    auto ends = [&](std::size_t side) {
        const Triangle& tri = triangles_[side / 3];
        const std::uint32_t from = tri[side % 3], to = tri[(side % 3 + 1) % 3];
        return std::pair{std::min(from, to), std::max(from, to)};
    };
    for (std::size_t side = 0; side < sides; ++side) ++first_side[ends(side).first + 1];
    for (std::size_t v = 0; v < vertices_.size(); ++v) first_side[v + 1] += first_side[v];
    std::vector<std::uint32_t> by_vertex(sides);
    {
        std::vector<std::uint32_t> cursor(first_side.begin(), first_side.end() - 1);
        for (std::size_t side = 0; side < sides; ++side) by_vertex[cursor[ends(side).first]++] = static_cast<std::uint32_t>(side);
    }
    edge_normals_.resize(n);
    closed_ = true;
    for (std::size_t v = 0; v < vertices_.size(); ++v) {
        const auto begin = by_vertex.begin() + first_side[v], end = by_vertex.begin() + first_side[v + 1];
        std::sort(begin, end, [&](std::uint32_t x, std::uint32_t y) {
            const std::uint32_t ux = ends(x).second, uy = ends(y).second;
            return ux != uy ? ux < uy : x < y;
        });
        for (auto group = begin; group != end;) {
            const std::uint32_t upper = ends(*group).second;
            auto group_end = group;
            glm::dvec3 sum(0.0);
            int forward = 0, backward = 0;
            for (; group_end != end && ends(*group_end).second == upper; ++group_end) {
                sum += face_normals_[*group_end / 3];
                const Triangle& tri = triangles_[*group_end / 3];
                (tri[*group_end % 3] < tri[(*group_end % 3 + 1) % 3] ? forward : backward) += 1;
            }
            closed_ = closed_ && forward == 1 && backward == 1;
            const double length = glm::length(sum);
            for (auto side = group; side != group_end; ++side) {
                edge_normals_[*side / 3][*side % 3] = length > 0.0 ? sum / length : face_normals_[*side / 3];
            }
            group = group_end;
        }
    }
    order_.resize(n);
    for (std::size_t t = 0; t < n; ++t) order_[t] = static_cast<std::uint32_t>(t);
    std::vector<glm::dvec3> centres(n);
    for (std::size_t t = 0; t < n; ++t) {
        const Triangle& tri = triangles_[t];
        centres[t] = (vertices_[tri[0]] + vertices_[tri[1]] + vertices_[tri[2]]) / 3.0;
    }
    nodes_.reserve(2 * (n / kLeafTriangles + 1));
    build(0, static_cast<std::uint32_t>(n), centres);
}

std::uint32_t TriangleMesh::build(std::uint32_t first, std::uint32_t count, const std::vector<glm::dvec3>& centres) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    constexpr double kInf = std::numeric_limits<double>::infinity();
    nodes_.push_back(Node{glm::dvec3(kInf), glm::dvec3(-kInf), first, count});
    glm::dvec3 centre_lo(kInf), centre_hi(-kInf);
    for (std::uint32_t i = first; i < first + count; ++i) {
        centre_lo = glm::min(centre_lo, centres[order_[i]]);
        centre_hi = glm::max(centre_hi, centres[order_[i]]);
    }
    const glm::dvec3 extent = centre_hi - centre_lo;
    if (count <= kLeafTriangles || !(std::max({extent.x, extent.y, extent.z}) > 0.0)) {
        glm::dvec3 lo(kInf), hi(-kInf);
        for (std::uint32_t i = first; i < first + count; ++i) {
            for (std::uint32_t v : triangles_[order_[i]]) {
                lo = glm::min(lo, vertices_[v]);
                hi = glm::max(hi, vertices_[v]);
            }
        }
        nodes_[index].lo = lo;
        nodes_[index].hi = hi;
        return index;
    }
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const std::uint32_t half = count / 2;
    // The split on a copy of the keys beside the indices: nth_element then reads them in order instead of
    // gathering centres (the same comparisons, so the same split).
    std::vector<std::pair<double, std::uint32_t>> keyed(count);
    for (std::uint32_t i = 0; i < count; ++i) keyed[i] = {centres[order_[first + i]][axis], order_[first + i]};
    std::nth_element(keyed.begin(), keyed.begin() + half, keyed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::uint32_t i = 0; i < count; ++i) order_[first + i] = keyed[i].second;
    const std::uint32_t left = build(first, half, centres);
    const std::uint32_t right = build(first + half, count - half, centres);
    // The box of the triangles below: the children's together (min and max are exact).
    nodes_[index].lo = glm::min(nodes_[left].lo, nodes_[right].lo);
    nodes_[index].hi = glm::max(nodes_[left].hi, nodes_[right].hi);
    nodes_[index].count = 0;
    nodes_[index].first = right;
    return index;
}

// Triangle t's closest point to p when it is nearer than best2 (and, once one is `found`, strictly nearer):
// then best2 becomes its squared distance and `out` the point. Inlined into both searches' loops.
[[gnu::always_inline]] inline bool TriangleMesh::closest_of(glm::dvec3 p, std::uint32_t t, double& best2, bool found,
                                                            Nearest& out) const {
    const Triangle& tri = triangles_[t];
    const glm::dvec3 a = vertices_[tri[0]];
    // The distance to the triangle's plane bounds the distance to the triangle from below.
    const double plane = glm::dot(p - a, face_normals_[t]);
    if (found ? plane * plane >= best2 : plane * plane > best2) return false;
    // So does the distance to its bounding sphere: a triangle in the list beside the particle, not under it
    // (most of a contact grid cell's), is passed over for a dot product instead of the closest point. Widened
    // by a relative 1e-9, far beyond the rounding of the sphere, so no triangle that could be the nearest is
    // passed over. (Tested first, before the plane, it took a square root for every listing: 1.2x slower.)
    const glm::dvec4 sphere = spheres_[t];
    const glm::dvec3 to_centre = p - glm::dvec3(sphere);
    const double reach = std::sqrt(best2) + sphere.w;
    if (glm::dot(to_centre, to_centre) > reach * reach * (1.0 + 1e-9)) return false;
    const Closest c = closest_on_triangle(p, a, vertices_[tri[1]], vertices_[tri[2]]);
    const glm::dvec3 d = p - c.point;
    const double d2 = glm::dot(d, d);
    if (found ? !(d2 < best2) : !(d2 <= best2)) return false;  // a NaN is never nearer
    best2 = d2;
    const glm::dvec3 normal = c.feature == Feature::Face     ? face_normals_[t]
                              : c.feature == Feature::Edge   ? edge_normals_[t][c.index]
                                                             : vertex_normals_[tri[c.index]];
    out = Nearest{c.point, 0.0, normal, glm::dot(d, normal) < 0.0, t};
    return true;
}

std::optional<TriangleMesh::Nearest> TriangleMesh::nearest(glm::dvec3 p, double radius) const {
    Nearest out{};
    bool found = false;
    double best2 = radius * radius;
    std::uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    // Once a point is found, a box no nearer than it cannot hold a nearer one (ties keep the first).
    auto beyond = [&](double d2) { return found ? d2 >= best2 : d2 > best2; };
    while (top > 0) {
        const Node& node = nodes_[stack[--top]];
        if (beyond(box_distance2(p, node.lo, node.hi))) continue;
        if (node.count == 0) {
            const std::uint32_t left = static_cast<std::uint32_t>(&node - nodes_.data()) + 1, right = node.first;
            const double dl = box_distance2(p, nodes_[left].lo, nodes_[left].hi);
            const double dr = box_distance2(p, nodes_[right].lo, nodes_[right].hi);
            // The nearer child last, so it is searched first and prunes the other.
            if (top + 2 > 64) continue;  // deeper than a median split of 2^32 triangles goes: never
            if (dl < dr) stack[top++] = right, stack[top++] = left;
            else stack[top++] = left, stack[top++] = right;
            continue;
        }
        for (std::uint32_t i = node.first; i < node.first + node.count; ++i) found |= closest_of(p, order_[i], best2, found, out);
    }
    if (!found) return std::nullopt;
    out.distance = std::sqrt(best2);
    return out;
}

std::optional<TriangleMesh::Nearest> TriangleMesh::nearest(glm::dvec3 p, double radius, const ContactGrid& grid) const {
    Nearest out{};
    bool found = false;
    double best2 = radius * radius;
    const std::size_t c = grid.cell_of(p);
    if (c == ContactGrid::kNone) return std::nullopt;  // outside the grid: nothing within the band
    for (std::uint32_t i = grid.start[c]; i < grid.start[c + 1]; ++i) found |= closest_of(p, grid.triangles[i], best2, found, out);
    if (!found) return std::nullopt;
    out.distance = std::sqrt(best2);
    return out;
}

std::shared_ptr<const ContactGrid> TriangleMesh::contact_grid(double band) const {
    {
        std::lock_guard lock(grids_->mutex);
        for (const auto& g : grids_->recent) {
            if (g->band == band) return g;
        }
    }
    auto grid = std::make_shared<ContactGrid>();
    grid->band = band;
    // Cells about half as large as the triangles' edges (and at least two bands): a cell then lists a few of
    // them. At most kMaxCells cells and kMaxEntries listings: larger cells where the mesh's box is large beside
    // its triangles, or its triangles large beside the band.
    constexpr double kMaxCells = 4e6, kMaxEntries = 16e6;
    double edges = 0.0;
    for (const Triangle& t : triangles_) edges += glm::length(vertices_[t[1]] - vertices_[t[0]]);
    const glm::dvec3 lo = this->lo() - glm::dvec3(band), extent = this->hi() - this->lo() + glm::dvec3(2.0 * band);
    double cell = std::max({0.5 * edges / static_cast<double>(triangles_.size()), 2.0 * band, 1e-9});
    // Triangle t's cells: its box grown by the band, clamped to the grid (of `size` cells of edge `cell`).
    std::array<int, 3> size{};
    auto range = [&](std::uint32_t t, std::array<int, 3>& from, std::array<int, 3>& to) {
        glm::dvec3 tlo(INFINITY), thi(-INFINITY);
        for (std::uint32_t v : triangles_[t]) tlo = glm::min(tlo, vertices_[v]), thi = glm::max(thi, vertices_[v]);
        for (int a = 0; a < 3; ++a) {
            const double top = size[a] - 1;
            from[a] = static_cast<int>(std::clamp(std::floor((tlo[a] - band - lo[a]) / cell), 0.0, top));
            to[a] = static_cast<int>(std::clamp(std::floor((thi[a] + band - lo[a]) / cell), 0.0, top));
        }
    };
    for (;;) {
        if ((extent.x / cell + 1.0) * (extent.y / cell + 1.0) * (extent.z / cell + 1.0) > kMaxCells) {
            cell *= 1.25;
            continue;
        }
        for (int a = 0; a < 3; ++a) size[a] = static_cast<int>(std::floor(extent[a] / cell)) + 1;
        double entries = 0.0;
        for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
            std::array<int, 3> from{}, to{};
            range(t, from, to);
            entries += double(to[0] - from[0] + 1) * (to[1] - from[1] + 1) * (to[2] - from[2] + 1);
        }
        if (entries <= kMaxEntries) break;
        cell *= 1.25;
    }
    grid->cell = cell;
    grid->origin = lo;
    grid->size = size;
    const std::size_t cells = static_cast<std::size_t>(size[0]) * size[1] * size[2];
    auto each_cell = [&](std::uint32_t t, auto&& visit) {
        std::array<int, 3> from{}, to{};
        range(t, from, to);
        for (int k = from[2]; k <= to[2]; ++k) {
            for (int j = from[1]; j <= to[1]; ++j) {
                for (int i = from[0]; i <= to[0]; ++i) {
                    visit(static_cast<std::size_t>(i) + static_cast<std::size_t>(size[0]) * (j + static_cast<std::size_t>(size[1]) * k));
                }
            }
        }
    };
    // Of the cells its grown box meets, a triangle is listed in those whose centre lies within the band and half
    // the cell's diagonal of it: a point of the cell within the band of it lies no further from the centre.
    const double reach = band + 0.5 * std::sqrt(3.0) * cell;
    auto near_centre = [&](std::uint32_t t, std::size_t c) {
        const std::size_t i = c % grid->size[0], j = (c / grid->size[0]) % grid->size[1], k = c / (static_cast<std::size_t>(grid->size[0]) * grid->size[1]);
        const glm::dvec3 centre = lo + cell * glm::dvec3(i + 0.5, j + 0.5, k + 0.5);
        const Triangle& tri = triangles_[t];
        const glm::dvec3 d = centre - closest_on_triangle(centre, vertices_[tri[0]], vertices_[tri[1]], vertices_[tri[2]]).point;
        // Listed unless surely beyond: a triangle of next to no area (1e-42 m^2) can give a centre no finite
        // closest point, while a point of the cell still finds it (fuzz corpus: mesh/tiny-triangle-in-cell.obj).
        return !(glm::dot(d, d) > reach * reach * (1.0 + 1e-9));
    };
    grid->start.assign(cells + 1, 0);
    for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
        each_cell(t, [&](std::size_t c) { grid->start[c + 1] += near_centre(t, c); });
    }
    for (std::size_t c = 0; c < cells; ++c) grid->start[c + 1] += grid->start[c];
    grid->triangles.resize(grid->start[cells]);
    std::vector<std::uint32_t> next(grid->start.begin(), grid->start.end() - 1);
    for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
        each_cell(t, [&](std::size_t c) {
            if (near_centre(t, c)) grid->triangles[next[c]++] = t;
        });
    }
    if (closed_) classify_empty_cells(*grid);
    std::lock_guard lock(grids_->mutex);
    grids_->recent.push_back(grid);
    if (grids_->recent.size() > 4) grids_->recent.erase(grids_->recent.begin());
    return grid;
}

void TriangleMesh::classify_empty_cells(ContactGrid& grid) const {
    const std::size_t cells = grid.start.size() - 1;
    const std::size_t nx = static_cast<std::size_t>(grid.size[0]), ny = static_cast<std::size_t>(grid.size[1]);
    const std::size_t nz = static_cast<std::size_t>(grid.size[2]);
    // 0: not yet reached (or a cell that lists triangles); 1: outside; 2: inside.
    std::vector<std::uint8_t> side(cells, 0);
    std::vector<std::size_t> stack;
    for (std::size_t seed = 0; seed < cells; ++seed) {
        if (side[seed] != 0 || grid.start[seed + 1] != grid.start[seed]) continue;
        const std::size_t i = seed % nx, j = (seed / nx) % ny, k = seed / (nx * ny);
        const glm::dvec3 centre = grid.origin + grid.cell * (glm::dvec3(double(i), double(j), double(k)) + 0.5);
        const auto near = nearest(centre, INFINITY);
        const std::uint8_t region = near && near->inside ? 2 : 1;
        side[seed] = region;
        stack.push_back(seed);
        while (!stack.empty()) {
            const std::size_t c = stack.back();
            stack.pop_back();
            const std::size_t ci = c % nx, cj = (c / nx) % ny, ck = c / (nx * ny);
            auto reach = [&](bool exists, std::size_t n) {
                if (exists && side[n] == 0 && grid.start[n + 1] == grid.start[n]) {
                    side[n] = region;
                    stack.push_back(n);
                }
            };
            reach(ci > 0, c - 1);
            reach(ci + 1 < nx, c + 1);
            reach(cj > 0, c - nx);
            reach(cj + 1 < ny, c + nx);
            reach(ck > 0, c - nx * ny);
            reach(ck + 1 < nz, c + nx * ny);
        }
    }
    grid.inside.resize(cells);
    for (std::size_t c = 0; c < cells; ++c) grid.inside[c] = side[c] == 2;
}

std::optional<TriangleMesh::Crossing> TriangleMesh::first_crossing(glm::dvec3 p0, glm::dvec3 p1, bool front_only) const {
    const glm::dvec3 d = p1 - p0;
    std::optional<Crossing> best;
    double best_t = 1.0;
    std::uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    // Barycentric slack: a path through a shared edge or vertex meets one of its triangles despite rounding.
    constexpr double kSlack = 1e-9;
    while (top > 0) {
        const std::uint32_t at = stack[--top];
        const Node& node = nodes_[at];
        if (!segment_meets_box(p0, d, best_t, node.lo - glm::dvec3(1e-9), node.hi + glm::dvec3(1e-9))) continue;
        if (node.count == 0) {
            if (top + 2 > 64) continue;
            stack[top++] = node.first;
            stack[top++] = at + 1;
            continue;
        }
        for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
            const std::uint32_t t = order_[i];
            const Triangle& tri = triangles_[t];
            const glm::dvec3 a = vertices_[tri[0]];
            const glm::dvec3 e1 = vertices_[tri[1]] - a, e2 = vertices_[tri[2]] - a;
            const glm::dvec3 h = glm::cross(d, e2);
            const double det = glm::dot(e1, h);
            // det = -(d . (e1 x e2)): positive when the path runs against the outward normal (from outside in).
            if (!(std::fabs(det) > 0.0) || (front_only && det < 0.0)) continue;
            const double inv = 1.0 / det;
            const glm::dvec3 s = p0 - a;
            const double u = inv * glm::dot(s, h);
            if (u < -kSlack || u > 1.0 + kSlack) continue;
            const glm::dvec3 q = glm::cross(s, e1);
            const double v = inv * glm::dot(d, q);
            if (v < -kSlack || u + v > 1.0 + kSlack) continue;
            const double hit = inv * glm::dot(e2, q);
            if (hit < 0.0 || hit > best_t || (best && hit == best_t)) continue;
            best_t = hit;
            best = Crossing{hit, face_normals_[t], t};
        }
    }
    return best;
}

bool TriangleMesh::may_touch(glm::dvec3 lo, glm::dvec3 hi) const {
    std::uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const std::uint32_t at = stack[--top];
        const Node& node = nodes_[at];
        if (node.lo.x > hi.x || node.hi.x < lo.x || node.lo.y > hi.y || node.hi.y < lo.y || node.lo.z > hi.z ||
            node.hi.z < lo.z) {
            continue;
        }
        if (node.count != 0) {
            // A leaf of a few triangles: their joint box is near enough to each one's.
            return true;
        }
        if (top + 2 > 64) return true;
        stack[top++] = node.first;
        stack[top++] = at + 1;
    }
    return false;
}

double TriangleMesh::winding_number(glm::dvec3 p) const {
    // Each triangle's signed solid angle by Van Oosterom & Strackee's formula (IEEE Trans. Biomed. Eng. 30(2),
    // 1983): tan(omega / 2) = a . (b x c) / (|a||b||c| + (a . b)|c| + (b . c)|a| + (c . a)|b|).
    double total = 0.0;
    for (const Triangle& tri : triangles_) {
        const glm::dvec3 a = vertices_[tri[0]] - p, b = vertices_[tri[1]] - p, c = vertices_[tri[2]] - p;
        const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
        const double numerator = glm::dot(a, glm::cross(b, c));
        const double denominator = la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
        total += 2.0 * std::atan2(numerator, denominator);
    }
    return total / (4.0 * std::numbers::pi);
}

}  // namespace clothsim
