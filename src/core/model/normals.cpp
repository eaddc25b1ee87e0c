#include "clothsim/normals.hpp"

#include "integrators/fast_solver.hpp"
#include "integrators/work_team.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <thread>

namespace clothsim {
namespace {

glm::vec3 unit_or_up(glm::vec3 n) {
    const float length = glm::length(n);
    return length > 1e-20f ? n / length : glm::vec3(0.0f, 1.0f, 0.0f);
}

// Any triangle list: each triangle adds its cross product to its three corners, in list order.
void normals_of_triangles(const Topology& topology, const DVec3Array& position, std::vector<glm::vec3>& normals) {
    for (const auto& t : topology.triangles) {
        // Edges in double, rounded to float: what is drawn needs no more.
        const glm::dvec3 a = position.get(t[0]);
        const glm::vec3 n = glm::cross(glm::vec3(position.get(t[1]) - a), glm::vec3(position.get(t[2]) - a));
        normals[t[0]] += n;
        normals[t[1]] += n;
        normals[t[2]] += n;
    }
    for (glm::vec3& n : normals) n = unit_or_up(n);
}

// One row of cells' triangle normals, as structure of arrays over the cell column (a loop GCC vectorises):
// first = (p01 - p00) x (p10 - p00), second = (p11 - p01) x (p10 - p01), the triangles' own edges.
struct CellRow {
    std::vector<float> first[3], second[3];
    void resize(int cells) {
        for (auto* v : {first, second}) {
            for (int k = 0; k < 3; ++k) v[k].assign(static_cast<std::size_t>(cells), 0.0f);
        }
    }
};

[[gnu::always_inline]] inline void cell_row(const DVec3Array& position, int cols, int r, CellRow& out) {
    const std::size_t top = static_cast<std::size_t>(r) * cols, bottom = top + cols;
    const double* p[3] = {position.x.data(), position.y.data(), position.z.data()};
    float* f[3] = {out.first[0].data(), out.first[1].data(), out.first[2].data()};
    float* s[3] = {out.second[0].data(), out.second[1].data(), out.second[2].data()};
    const double *x0 = p[0] + top, *y0 = p[1] + top, *z0 = p[2] + top;
    const double *x1 = p[0] + bottom, *y1 = p[1] + bottom, *z1 = p[2] + bottom;
    // The six output rows are distinct vectors: without the pragma GCC wants more alias checks than it will
    // emit and leaves the loop scalar.
#pragma GCC ivdep
    for (int c = 0; c + 1 < cols; ++c) {
        // first: e = p01 - p00, g = p10 - p00; second: e = p11 - p01, g = p10 - p01 (glm::cross's order).
        const float ex = static_cast<float>(x0[c + 1] - x0[c]), ey = static_cast<float>(y0[c + 1] - y0[c]),
                    ez = static_cast<float>(z0[c + 1] - z0[c]);
        const float gx = static_cast<float>(x1[c] - x0[c]), gy = static_cast<float>(y1[c] - y0[c]),
                    gz = static_cast<float>(z1[c] - z0[c]);
        f[0][c] = ey * gz - gy * ez;
        f[1][c] = ez * gx - gz * ex;
        f[2][c] = ex * gy - gx * ey;
        const float hx = static_cast<float>(x1[c + 1] - x0[c + 1]), hy = static_cast<float>(y1[c + 1] - y0[c + 1]),
                    hz = static_cast<float>(z1[c + 1] - z0[c + 1]);
        const float kx = static_cast<float>(x1[c] - x0[c + 1]), ky = static_cast<float>(y1[c] - y0[c + 1]),
                    kz = static_cast<float>(z1[c] - z0[c + 1]);
        s[0][c] = hy * kz - ky * hz;
        s[1][c] = hz * kx - kz * hx;
        s[2][c] = hx * ky - kx * hy;
    }
}

// Vertex rows [begin, end) of a grid whose triangles are cell_triangles. Vertex (r, c) sums, in the order
// the triangle list visits them (so the result is the list's, bit for bit): cell (r-1, c-1)'s second,
// cell (r-1, c)'s first and second, cell (r, c-1)'s first and second, cell (r, c)'s first. Inner vertices
// of inner rows take a branch-free loop over structure-of-arrays rows (vectorised); the rest the general
// sum, which skips the cells that do not exist.
[[gnu::always_inline]] inline void grid_rows_body(const Topology& topology, const DVec3Array& position, int begin,
                                                  int end, std::vector<glm::vec3>& normals) {
    const int rows = topology.rows, cols = topology.cols;
    CellRow above, below;
    above.resize(cols - 1);
    below.resize(cols - 1);
    std::vector<float> sum[3];
    for (auto& v : sum) v.assign(static_cast<std::size_t>(cols), 0.0f);
    if (begin > 0) cell_row(position, cols, begin - 1, above);
    auto first = [](const CellRow& row, int c) { return glm::vec3(row.first[0][c], row.first[1][c], row.first[2][c]); };
    auto second = [](const CellRow& row, int c) {
        return glm::vec3(row.second[0][c], row.second[1][c], row.second[2][c]);
    };
    for (int r = begin; r < end; ++r) {
        if (r + 1 < rows) cell_row(position, cols, r, below);
        glm::vec3* out = normals.data() + static_cast<std::size_t>(r) * cols;
        auto general = [&](int c) {
            glm::vec3 n(0.0f);
            if (r > 0) {
                if (c > 0) n += second(above, c - 1);
                if (c + 1 < cols) {
                    n += first(above, c);
                    n += second(above, c);
                }
            }
            if (r + 1 < rows) {
                if (c > 0) {
                    n += first(below, c - 1);
                    n += second(below, c - 1);
                }
                if (c + 1 < cols) n += first(below, c);
            }
            out[c] = unit_or_up(n);
        };
        if (r == 0 || r + 1 == rows || cols < 3) {
            for (int c = 0; c < cols; ++c) general(c);
        } else {
            general(0);
            for (int k = 0; k < 3; ++k) {
                const float* af = above.first[k].data();
                const float* as = above.second[k].data();
                const float* bf = below.first[k].data();
                const float* bs = below.second[k].data();
                float* n = sum[k].data();
                for (int c = 1; c + 1 < cols; ++c) {
                    // From 0, as the list's sum starts: 0 + a is a except for a = -0 (0 + -0 = +0).
                    n[c] = 0.0f + as[c - 1] + af[c] + as[c] + bf[c - 1] + bs[c - 1] + bf[c];
                }
            }
            // unit_or_up, as arrays: the same sqrt of ((x x + y y) + z z) and the same divides.
            float* nx = sum[0].data();
            float* ny = sum[1].data();
            float* nz = sum[2].data();
            for (int c = 1; c + 1 < cols; ++c) {
                const float length = std::sqrt(nx[c] * nx[c] + ny[c] * ny[c] + nz[c] * nz[c]);
                const bool some = length > 1e-20f;
                const float divisor = some ? length : 1.0f;
                nx[c] = some ? nx[c] / divisor : 0.0f;
                ny[c] = some ? ny[c] / divisor : 1.0f;
                nz[c] = some ? nz[c] / divisor : 0.0f;
            }
            for (int c = 1; c + 1 < cols; ++c) out[c] = glm::vec3(nx[c], ny[c], nz[c]);
            general(cols - 1);
        }
        std::swap(above, below);
    }
}

// grid_rows_body compiled for each instruction set, chosen as the fast solver chooses its kernels
// (FastSolver::kernel). The core compiles without contraction into fused multiply-adds and every operation is
// element-wise IEEE, so all three give the triangle list's normals bit for bit.
void grid_rows_generic(const Topology& topology, const DVec3Array& position, int begin, int end,
                       std::vector<glm::vec3>& normals) {
    grid_rows_body(topology, position, begin, end, normals);
}
__attribute__((target("avx2,fma"))) void grid_rows_avx2(const Topology& topology, const DVec3Array& position,
                                                         int begin, int end, std::vector<glm::vec3>& normals) {
    grid_rows_body(topology, position, begin, end, normals);
}
__attribute__((target("avx512f,avx512vl,avx2,fma,prefer-vector-width=512"))) void grid_rows_avx512(
    const Topology& topology, const DVec3Array& position, int begin, int end, std::vector<glm::vec3>& normals) {
    grid_rows_body(topology, position, begin, end, normals);
}
using GridRows = void (*)(const Topology&, const DVec3Array&, int, int, std::vector<glm::vec3>&);
GridRows grid_rows_kernel() {
    switch (FastSolver::kernel()) {
        case FastKernel::Avx512: return grid_rows_avx512;
        case FastKernel::Avx2: return grid_rows_avx2;
        case FastKernel::Generic: break;
    }
    return grid_rows_generic;
}

}  // namespace

void compute_vertex_normals(const Topology& topology, const DVec3Array& position, std::vector<glm::vec3>& normals) {
    const bool grid = topology.cell_triangles &&
                      position.size() == static_cast<std::size_t>(topology.rows) * topology.cols;
    if (!grid) {
        normals.assign(position.size(), glm::vec3(0.0f));
        normals_of_triangles(topology, position, normals);
        return;
    }
    normals.resize(position.size());  // every vertex is written below
    if (position.size() == 0) return;
    const GridRows grid_rows = grid_rows_kernel();
    // Bands of rows, one per thread from 128 rows of 128 on (below that a team costs more than it saves); each
    // band recomputes the one cell row above it, so no two threads write the same vertex.
    const int cores = WorkTeam::cores();
    const int rows = topology.rows;
    const int bands = std::clamp(static_cast<int>(position.size() / (128 * 128)), 1, std::min(cores, rows));
    if (bands == 1) {
        grid_rows(topology, position, 0, rows, normals);
        return;
    }
    WorkTeam::shared().run(bands, bands, [&](int b, int) {
        grid_rows(topology, position, rows * b / bands, rows * (b + 1) / bands, normals);
    });
}

}  // namespace clothsim
