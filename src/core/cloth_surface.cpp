#include "clothsim/cloth_surface.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <unordered_map>

namespace clothsim {
namespace {

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | b;
}


}  // namespace

ClothSurface build_cloth_surface(const Topology& topology, const std::vector<std::uint8_t>& pinned,
                                 const DVec3Array& rest) {
    ClothSurface surface;
    const int rows = topology.rows, cols = topology.cols;
    const std::size_t n = rest.size();
    surface.particles = n;
    if (rows < 2 || cols < 2 || n != static_cast<std::size_t>(rows) * cols || pinned.size() != n) return surface;

    auto id = [&](int r, int c) { return static_cast<std::uint32_t>(topology.index(r, c)); };
    auto present = [&](int r, int c) { return pinned[topology.index(r, c)] != kAbsent; };
    auto row = [&](std::uint32_t v) { return static_cast<int>(v) / cols; };
    auto col = [&](std::uint32_t v) { return static_cast<int>(v) % cols; };
    // The grid cell a triangle lies in (row and column of its corner 00), or -1 when it is no cell's.
    auto cell_of = [&](const std::array<std::uint32_t, 3>& t) {
        int r0 = rows, c0 = cols, r1 = -1, c1 = -1;
        for (std::uint32_t v : t) {
            r0 = std::min(r0, row(v)), r1 = std::max(r1, row(v)), c0 = std::min(c0, col(v)), c1 = std::max(c1, col(v));
        }
        return r1 - r0 == 1 && c1 - c0 == 1 ? static_cast<std::ptrdiff_t>(r0) * (cols - 1) + c0 : -1;
    };
    // Per cell, which of its two triangles are drawn: 1 for (00, 01, 10), 2 for (01, 11, 10).
    const std::size_t cells = static_cast<std::size_t>(rows - 1) * (cols - 1);
    std::vector<std::uint8_t> drawn(cells, 0);
    for (const auto& t : topology.triangles) {
        const std::ptrdiff_t cell = cell_of(t);
        if (cell < 0) continue;
        const std::uint32_t corner_00 = id(static_cast<int>(cell) / (cols - 1), static_cast<int>(cell) % (cols - 1));
        const bool has_00 = t[0] == corner_00 || t[1] == corner_00 || t[2] == corner_00;
        drawn[static_cast<std::size_t>(cell)] |= has_00 ? 1 : 2;
    }
    // A torn cell: all four corners belong to the cloth and a triangle of the cell is gone.
    std::vector<std::uint8_t> torn_cell(cells, 0);
    bool any = false;
    for (int r = 0; r + 1 < rows; ++r) {
        for (int c = 0; c + 1 < cols; ++c) {
            const std::size_t cell = static_cast<std::size_t>(r) * (cols - 1) + c;
            torn_cell[cell] = present(r, c) && present(r, c + 1) && present(r + 1, c) && present(r + 1, c + 1) &&
                              drawn[cell] != 3;
            any = any || torn_cell[cell];
        }
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
        const std::ptrdiff_t cell = cell_of(t);
        if (cell < 0 || !torn_cell[static_cast<std::size_t>(cell)]) surface.triangles.push_back(t);
    }

    // Edge points, one per held edge and one per end of a broken edge, each made once.
    std::unordered_map<std::uint64_t, std::uint32_t> edge_vertex;
    auto place = [&](std::uint32_t v) { return glm::vec2(float(col(v)), float(row(v))); };
    auto edge_point = [&](std::uint32_t from, std::uint32_t to) {
        const bool whole = holds(from, to);
        const std::uint64_t key = whole ? pair_key(from, to) : ((static_cast<std::uint64_t>(from) << 32) | to);
        const auto found = edge_vertex.find(key);
        if (found != edge_vertex.end()) return found->second;
        ClothSurface::EdgePoint e;
        e.from = from;
        e.to = to;
        e.whole = whole;
        e.back = ClothSurface::kNoParticle;
        e.half_rest = static_cast<float>(0.5 * glm::length(rest.get(to) - rest.get(from)));
        if (!whole) {
            // The particle on the other side of `from`, in line with the edge.
            const int rb = 2 * row(from) - row(to), cb = 2 * col(from) - col(to);
            if (rb >= 0 && rb < rows && cb >= 0 && cb < cols && present(rb, cb) && holds(id(rb, cb), from)) {
                e.back = id(rb, cb);
            }
        }
        const auto index = static_cast<std::uint32_t>(surface.particles + surface.edge_points.size());
        surface.edge_points.push_back(e);
        surface.split_grid.push_back(0.5f * (place(from) + place(to)));
        edge_vertex.emplace(key, index);
        return index;
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
    for_each_torn_cell([&](int, int, const std::array<std::uint32_t, 4>& k) {
        for (int i = 0; i < 4; ++i) {
            edge_point(k[i], k[(i + 1) % 4]);
            edge_point(k[i], k[(i + 3) % 4]);
        }
    });
    const auto first_centre = static_cast<std::uint32_t>(surface.particles + surface.edge_points.size());
    for_each_torn_cell([&](int r, int c, const std::array<std::uint32_t, 4>& k) {
        // The cell's pieces: corners joined by a held edge or diagonal.
        std::array<int, 4> piece = {0, 1, 2, 3};
        auto find = [&](int i) {
            while (piece[i] != i) i = piece[i];
            return i;
        };
        for (int i = 0; i < 4; ++i) {
            for (int j = i + 1; j < 4; ++j) {
                if (holds(k[i], k[j])) piece[std::max(find(i), find(j))] = std::min(find(i), find(j));
            }
        }
        std::array<std::uint32_t, 4> centre_of{};
        for (int i = 0; i < 4; ++i) {
            const std::uint32_t next = edge_point(k[i], k[(i + 1) % 4]), prev = edge_point(k[i], k[(i + 3) % 4]);
            const int root = find(i);
            if (root == i) {
                centre_of[i] = static_cast<std::uint32_t>(surface.centres.size());
                surface.centres.emplace_back();
                surface.split_grid.push_back(glm::vec2(float(c) + 0.5f, float(r) + 0.5f));
            } else {
                centre_of[i] = centre_of[root];
            }
            ClothSurface::Centre& centre = surface.centres[centre_of[i]];
            centre.corner[centre.count++] = {k[i], next, prev};
            const std::uint32_t middle = first_centre + centre_of[i];
            surface.triangles.push_back({k[i], next, middle});
            surface.triangles.push_back({k[i], middle, prev});
        }
    });
    return surface;
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
        } else if (e.back != ClothSurface::kNoParticle) {
            point = p + 0.5f * (p - vertices[e.back]);
        } else {
            const float length = glm::length(q - p);
            point = length > 0.0f ? p + (std::min(0.5f * length, e.half_rest) / length) * (q - p) : p;
        }
        vertices[first_edge + i] = point;
    }
    const std::size_t first_centre = first_edge + surface.edge_points.size();
    for (std::size_t i = 0; i < surface.centres.size(); ++i) {
        const ClothSurface::Centre& centre = surface.centres[i];
        glm::vec3 sum(0.0f);
        for (int k = 0; k < centre.count; ++k) {
            const auto& [p, e1, e2] = centre.corner[k];
            sum += vertices[e1] + vertices[e2] - vertices[p];
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
