#include "clothsim/cloth_surface.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

namespace clothsim {
namespace {

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | b;
}

// The grid cell (row-major over (rows - 1) x (cols - 1)) of which `t` is one of the builder's two triangles,
// with `which` = 1 for (00, 01, 10) and 2 for (01, 11, 10); -1 for any other triangle.
std::ptrdiff_t builder_cell(const Topology& topology, const std::array<std::uint32_t, 3>& t, int& which) {
    const int rows = topology.rows, cols = topology.cols;
    std::array<std::uint32_t, 3> s = t;
    std::sort(s.begin(), s.end());
    // The smallest index is the cell's 00 in (00, 01, 10) and its 01 in (01, 11, 10).
    const int r = static_cast<int>(s[0]) / cols, c = static_cast<int>(s[0]) % cols;
    if (r + 1 >= rows) return -1;
    const auto at = [&](int dr, int dc) { return static_cast<std::uint32_t>(topology.index(r + dr, c + dc)); };
    if (c + 1 < cols && s == std::array<std::uint32_t, 3>{at(0, 0), at(0, 1), at(1, 0)}) {
        which = 1;
        return static_cast<std::ptrdiff_t>(r) * (cols - 1) + c;
    }
    if (c > 0 && s == std::array<std::uint32_t, 3>{at(0, 0), at(1, -1), at(1, 0)}) {
        which = 2;
        return static_cast<std::ptrdiff_t>(r) * (cols - 1) + c - 1;
    }
    return -1;
}

// Per grid cell, which of the builder's two triangles the topology has (the bits of builder_cell's `which`);
// empty when the topology is not a grid of rows x cols particles.
std::vector<std::uint8_t> drawn_cells(const Topology& topology, std::size_t particles) {
    const int rows = topology.rows, cols = topology.cols;
    if (rows < 2 || cols < 2 || particles != static_cast<std::size_t>(rows) * cols) return {};
    std::vector<std::uint8_t> drawn(static_cast<std::size_t>(rows - 1) * (cols - 1), 0);
    for (const auto& t : topology.triangles) {
        int which = 0;
        const std::ptrdiff_t cell = builder_cell(topology, t, which);
        if (cell >= 0) drawn[static_cast<std::size_t>(cell)] |= static_cast<std::uint8_t>(which);
    }
    return drawn;
}

// The split surface's edge points, each made once: one per held edge, shared by its two cells, and one per end
// of a broken edge. `back(from, to)` (the particle the end's own row continues from) and `place(from, to)` (for
// its UV) are asked only of a new one.
class EdgePoints {
public:
    EdgePoints(ClothSurface& surface, const DVec3Array& rest) : surface_(surface), rest_(rest) {}
    template <class Back, class Place>
    std::uint32_t get(std::uint32_t from, std::uint32_t to, bool whole, Back&& back, Place&& place) {
        const std::uint64_t key = whole ? pair_key(from, to) : ((static_cast<std::uint64_t>(from) << 32) | to);
        const auto found = made_.find(key);
        if (found != made_.end()) return found->second;
        ClothSurface::EdgePoint e;
        e.from = from;
        e.to = to;
        e.whole = whole;
        e.back = whole ? ClothSurface::kNoParticle : back(from, to);
        e.half_rest = static_cast<float>(0.5 * glm::length(rest_.get(to) - rest_.get(from)));
        const auto index = static_cast<std::uint32_t>(surface_.particles + surface_.edge_points.size());
        surface_.edge_points.push_back(e);
        surface_.split_place.push_back(place(from, to));
        made_.emplace(key, index);
        return index;
    }

private:
    ClothSurface& surface_;
    const DVec3Array& rest_;
    std::unordered_map<std::uint64_t, std::uint32_t> made_;
};

// Makes the edge points of a torn cell's sides, from each corner to the next and to the previous, before any
// cell's centre, so that the centres' vertices follow all edge points.
template <std::size_t N, class EdgePoint>
void make_edge_points(const std::array<std::uint32_t, N>& k, EdgePoint&& edge_point) {
    for (std::size_t i = 0; i < N; ++i) {
        edge_point(k[i], k[(i + 1) % N]);
        edge_point(k[i], k[(i + N - 1) % N]);
    }
}

// One torn cell, its N corners `k` in the winding of its triangles: each corner's quadrilateral (the corner, its
// edge points towards the next and the previous corner, its piece's centre) as two triangles. Corners joined by
// a held spring (`holds`: an edge or, on the grid, a diagonal) form a piece with one centre, placed at `place`;
// `edge_point(from, to)` gives the points, made already. The centres' vertices start at `first_centre`.
template <std::size_t N, class Holds, class EdgePoint>
void split_cell(const std::array<std::uint32_t, N>& k, ClothSurface& surface, std::uint32_t first_centre, glm::vec2 place,
                Holds&& holds, EdgePoint&& edge_point) {
    std::array<std::size_t, N> piece{};
    for (std::size_t i = 0; i < N; ++i) piece[i] = i;
    auto find = [&](std::size_t i) {
        while (piece[i] != i) i = piece[i];
        return i;
    };
    for (std::size_t i = 0; i < N; ++i) {
        for (std::size_t j = i + 1; j < N; ++j) {
            if (holds(k[i], k[j])) piece[std::max(find(i), find(j))] = std::min(find(i), find(j));
        }
    }
    std::array<std::uint32_t, N> centre_of{};
    for (std::size_t i = 0; i < N; ++i) {
        const std::uint32_t next = edge_point(k[i], k[(i + 1) % N]), prev = edge_point(k[i], k[(i + N - 1) % N]);
        const std::size_t root = find(i);
        if (root == i) {
            centre_of[i] = static_cast<std::uint32_t>(surface.centres.size());
            surface.centres.emplace_back();
            surface.split_place.push_back(place);
        } else {
            centre_of[i] = centre_of[root];
        }
        ClothSurface::Centre& centre = surface.centres[centre_of[i]];
        centre.corner[static_cast<std::size_t>(centre.count++)] = {k[i], next, prev};
        const std::uint32_t middle = first_centre + centre_of[i];
        surface.triangles.push_back({k[i], next, middle});
        surface.triangles.push_back({k[i], middle, prev});
    }
}

}  // namespace

ClothCells cells_at_start(const Topology& topology, std::size_t particles) {
    ClothCells cells;
    if (topology.mesh) {
        cells.triangles = topology.triangles;
        return cells;
    }
    cells.whole = drawn_cells(topology, particles);
    for (std::uint8_t& cell : cells.whole) cell = cell == 3 ? 1 : 0;
    return cells;
}

namespace {

// A mesh cloth's surface: its torn triangles (in `built`, not in the topology's: tearing only removes) drawn as
// three corner quadrilaterals each.
ClothSurface build_mesh_surface(const Topology& topology, const DVec3Array& rest,
                                const std::vector<std::array<std::uint32_t, 3>>& built) {
    ClothSurface surface;
    surface.particles = rest.size();
    surface.mesh = true;
    const auto& present = topology.triangles;
    std::vector<std::array<std::uint32_t, 3>> torn;
    std::size_t next = 0;
    for (const auto& t : built) {
        if (next < present.size() && present[next] == t) ++next;
        else torn.push_back(t);
    }
    // Not a subsequence of the triangles as built (none are ever added): draw the topology as it is.
    if (torn.empty() || next != present.size() || topology.uv.size() != rest.size()) return surface;

    std::unordered_set<std::uint64_t> held;
    for (const Spring& sp : topology.springs) {
        if (sp.kind != SpringKind::Bending) held.insert(pair_key(sp.a, sp.b));
    }
    auto holds = [&](std::uint32_t a, std::uint32_t b) { return held.count(pair_key(a, b)) != 0; };
    surface.triangles = present;
    EdgePoints points(surface, rest);
    auto edge_point = [&](std::uint32_t from, std::uint32_t to) {
        // A mesh has no row to continue: a broken edge's end points at the other end.
        return points.get(from, to, holds(from, to), [](std::uint32_t, std::uint32_t) { return ClothSurface::kNoParticle; },
                          [&](std::uint32_t a, std::uint32_t b) { return 0.5f * (topology.uv[a] + topology.uv[b]); });
    };
    for (const auto& k : torn) make_edge_points(k, edge_point);
    const auto first_centre = static_cast<std::uint32_t>(surface.particles + surface.edge_points.size());
    for (const auto& k : torn) {
        const glm::vec2 centroid = (topology.uv[k[0]] + topology.uv[k[1]] + topology.uv[k[2]]) / 3.0f;
        split_cell(k, surface, first_centre, centroid, holds, edge_point);
    }
    return surface;
}

}  // namespace

ClothSurface build_cloth_surface(const Topology& topology, const DVec3Array& rest, const ClothCells& at_start) {
    if (topology.mesh) return build_mesh_surface(topology, rest, at_start.triangles);
    const std::vector<std::uint8_t>& whole_at_start = at_start.whole;
    ClothSurface surface;
    const int rows = topology.rows, cols = topology.cols;
    const std::size_t n = rest.size();
    surface.particles = n;
    const std::vector<std::uint8_t> drawn = drawn_cells(topology, n);
    if (drawn.empty() || whole_at_start.size() != drawn.size()) return surface;

    auto id = [&](int r, int c) { return static_cast<std::uint32_t>(topology.index(r, c)); };
    auto row = [&](std::uint32_t v) { return static_cast<int>(v) / cols; };
    auto col = [&](std::uint32_t v) { return static_cast<int>(v) % cols; };
    // A torn cell: it had both its triangles when the cloth was built and has lost one since.
    const std::size_t cells = drawn.size();
    std::vector<std::uint8_t> torn_cell(cells, 0);
    bool any = false;
    for (std::size_t cell = 0; cell < cells; ++cell) {
        torn_cell[cell] = whole_at_start[cell] && drawn[cell] != 3;
        any = any || torn_cell[cell];
    }
    if (!any) return surface;

    // Per particle, the structural and shear springs that still join it to the next row and column: bit 1
    // to (r, c + 1), 2 to (r + 1, c), 4 to (r + 1, c + 1), 8 to (r + 1, c - 1).
    auto link_bit = [&](std::uint32_t a, std::uint32_t b) {
        if (a > b) std::swap(a, b);
        const int dr = row(b) - row(a), dc = col(b) - col(a);
        if (dr == 0 && dc == 1) return 1;
        if (dr == 1 && dc == 0) return 2;
        if (dr == 1 && dc == 1) return 4;
        if (dr == 1 && dc == -1) return 8;
        return 0;
    };
    std::vector<std::uint8_t> links(n, 0);
    for (const Spring& sp : topology.springs) {
        if (sp.kind != SpringKind::Bending) links[std::min(sp.a, sp.b)] |= static_cast<std::uint8_t>(link_bit(sp.a, sp.b));
    }
    auto holds = [&](std::uint32_t a, std::uint32_t b) {
        const int bit = link_bit(a, b);
        return bit != 0 && (links[std::min(a, b)] & bit) != 0;
    };

    // The triangles of untorn cells and of anything that is not a cell's, as the topology has them.
    for (const auto& t : topology.triangles) {
        int which = 0;
        const std::ptrdiff_t cell = builder_cell(topology, t, which);
        if (cell < 0 || !torn_cell[static_cast<std::size_t>(cell)]) surface.triangles.push_back(t);
    }

    // Edge points, one per held edge and one per end of a broken edge, each made once. A broken edge's end
    // continues the particle on the other side of `from`, in line with the edge, when the spring to it holds.
    EdgePoints points(surface, rest);
    auto place = [&](std::uint32_t v) { return glm::vec2(float(col(v)), float(row(v))); };
    auto back = [&](std::uint32_t from, std::uint32_t to) {
        const int rb = 2 * row(from) - row(to), cb = 2 * col(from) - col(to);
        if (rb >= 0 && rb < rows && cb >= 0 && cb < cols && holds(id(rb, cb), from)) return id(rb, cb);
        return ClothSurface::kNoParticle;
    };
    auto edge_point = [&](std::uint32_t from, std::uint32_t to) {
        return points.get(from, to, holds(from, to), back,
                          [&](std::uint32_t a, std::uint32_t b) { return 0.5f * (place(a) + place(b)); });
    };

    // Around a cell counter-clockwise (00, 01, 11, 10): corner i's next edge goes to corner i + 1.
    auto corners = [&](int r, int c) {
        return std::array<std::uint32_t, 4>{id(r, c), id(r, c + 1), id(r + 1, c + 1), id(r + 1, c)};
    };
    auto for_each_torn_cell = [&](auto&& visit) {
        for (int r = 0; r + 1 < rows; ++r) {
            for (int c = 0; c + 1 < cols; ++c) {
                if (torn_cell[static_cast<std::size_t>(r) * (cols - 1) + c]) visit(r, c, corners(r, c));
            }
        }
    };
    for_each_torn_cell([&](int, int, const std::array<std::uint32_t, 4>& k) { make_edge_points(k, edge_point); });
    const auto first_centre = static_cast<std::uint32_t>(surface.particles + surface.edge_points.size());
    for_each_torn_cell([&](int r, int c, const std::array<std::uint32_t, 4>& k) {
        split_cell(k, surface, first_centre, glm::vec2(float(c) + 0.5f, float(r) + 0.5f), holds, edge_point);
    });
    return surface;
}

glm::vec2 grid_uv(const Topology& topology, glm::vec2 grid) {
    return {topology.cols > 1 ? grid.x / float(topology.cols - 1) : 0.0f,
            topology.rows > 1 ? 1.0f - grid.y / float(topology.rows - 1) : 0.0f};
}

void place_split_vertices(const ClothSurface& surface, std::vector<glm::vec3>& vertices) {
    vertices.resize(surface.vertex_count());
    const std::size_t first_edge = surface.particles;
    for (std::size_t i = 0; i < surface.edge_points.size(); ++i) {
        const ClothSurface::EdgePoint& e = surface.edge_points[i];
        const glm::vec3 p = vertices[e.from], q = vertices[e.to];
        glm::vec3 point;
        if (e.whole) {
            point = 0.5f * (p + q);
        } else {
            // The end's own row or column continued while it still points across the edge, else towards q; no
            // further than half the rest length nor halfway to q, so the two sides never overlap.
            const float gap = glm::length(q - p);
            glm::vec3 direction = q - p;
            float reach = std::min(0.5f * gap, e.half_rest);
            if (e.back != ClothSurface::kNoParticle && glm::dot(p - vertices[e.back], q - p) > 0.0f) {
                direction = p - vertices[e.back];
                reach = std::min(0.5f * glm::length(direction), reach);
            }
            const float length = glm::length(direction);
            point = length > 0.0f ? p + (reach / length) * direction : p;
        }
        vertices[first_edge + i] = point;
    }
    const std::size_t first_centre = first_edge + surface.edge_points.size();
    for (std::size_t i = 0; i < surface.centres.size(); ++i) {
        const ClothSurface::Centre& centre = surface.centres[i];
        glm::vec3 sum(0.0f);
        for (int k = 0; k < centre.count; ++k) {
            const auto& [p, e1, e2] = centre.corner[k];
            // A grid cell's quadrant ends at its parallelogram's fourth corner, a triangle's at its centroid.
            sum += surface.mesh ? (2.0f * (vertices[e1] + vertices[e2]) - vertices[p]) / 3.0f : vertices[e1] + vertices[e2] - vertices[p];
        }
        vertices[first_centre + i] = sum / float(std::max(centre.count, 1));
    }
}

void split_surface_normals(const ClothSurface& surface, const std::vector<glm::vec3>& vertices,
                           std::vector<glm::vec3>& normals) {
    normals.assign(vertices.size(), glm::vec3(0.0f));
    for (const auto& t : surface.triangles) {
        const glm::vec3 n = glm::cross(vertices[t[1]] - vertices[t[0]], vertices[t[2]] - vertices[t[0]]);
        for (std::uint32_t v : t) normals[v] += n;
    }
    for (glm::vec3& n : normals) {
        const float length = glm::length(n);
        n = length > 1e-20f ? n / length : glm::vec3(0.0f, 1.0f, 0.0f);
    }
}

}  // namespace clothsim
