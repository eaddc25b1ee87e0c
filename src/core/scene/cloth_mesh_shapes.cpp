#include "clothsim/cloth_mesh_shapes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <vector>

namespace clothsim {
namespace {

using Triangles = std::vector<TriangleMesh::Triangle>;

// Triangles between two rows of vertex indices running the same way: at each step the row whose next point lies
// less far along it advances. `closed`: both rows are loops.
void zip_rows(std::vector<std::uint32_t> a, std::vector<std::uint32_t> b, bool closed, Triangles& out) {
    if (closed) {
        a.push_back(a.front());
        b.push_back(b.front());
    }
    const std::size_t ea = a.size() - 1, eb = b.size() - 1;
    std::size_t i = 0, j = 0;
    while (i < ea || j < eb) {
        // (i + 1) / ea < (j + 1) / eb, in integers.
        if (j == eb || (i < ea && (i + 1) * eb < (j + 1) * ea)) {
            out.push_back({a[i], a[i + 1], b[j]});
            ++i;
        } else {
            out.push_back({a[i], b[j + 1], b[j]});
            ++j;
        }
    }
}

// a, then points about `edge` apart on to b (b included), at least one step.
void add_stations(std::vector<double>& out, double a, double b, double edge) {
    const int steps = std::max(1, static_cast<int>(std::lround((b - a) / edge)));
    if (out.empty()) out.push_back(a);
    for (int k = 1; k <= steps; ++k) out.push_back(k == steps ? b : a + (b - a) * k / steps);
}

double ellipse_perimeter(double a, double b) {  // Ramanujan's approximation
    return std::numbers::pi * (3.0 * (a + b) - std::sqrt((3.0 * a + b) * (a + 3.0 * b)));
}

}  // namespace

TriangleMesh cloth_disc(double radius, int rings) {
    std::vector<glm::dvec3> vertices = {glm::dvec3(0.0)};
    std::vector<std::vector<std::uint32_t>> rows = {{0}};
    for (int k = 1; k <= rings; ++k) {
        const double r = radius * k / rings;
        std::vector<std::uint32_t> row;
        for (int p = 0; p < 6 * k; ++p) {
            const double angle = 2.0 * std::numbers::pi * p / (6 * k);
            row.push_back(static_cast<std::uint32_t>(vertices.size()));
            vertices.emplace_back(r * std::cos(angle), 0.0, r * std::sin(angle));
        }
        rows.push_back(std::move(row));
    }
    Triangles triangles;
    for (std::size_t p = 0; p < rows[1].size(); ++p) triangles.push_back({0, rows[1][(p + 1) % rows[1].size()], rows[1][p]});
    for (int k = 1; k < rings; ++k) zip_rows(rows[k], rows[k + 1], true, triangles);
    return TriangleMesh(std::move(vertices), std::move(triangles));
}

int annulus_inner_count(double inner_a, double inner_b, double edge) {
    return std::max(6, static_cast<int>(std::lround(ellipse_perimeter(inner_a, inner_b) / edge)));
}

TriangleMesh cloth_annulus(double inner_a, double inner_b, double width, double edge) {
    const int rings = std::max(1, static_cast<int>(std::lround(width / edge)));
    std::vector<glm::dvec3> vertices;
    std::vector<std::vector<std::uint32_t>> rows;
    for (int k = 0; k <= rings; ++k) {
        const double a = inner_a + width * k / rings, b = inner_b + width * k / rings;
        const int count = annulus_inner_count(a, b, edge);
        std::vector<std::uint32_t> row;
        for (int p = 0; p < count; ++p) {
            const double angle = 2.0 * std::numbers::pi * p / count;
            row.push_back(static_cast<std::uint32_t>(vertices.size()));
            vertices.emplace_back(a * std::cos(angle), 0.0, b * std::sin(angle));
        }
        rows.push_back(std::move(row));
    }
    Triangles triangles;
    for (int k = 0; k < rings; ++k) zip_rows(rows[k], rows[k + 1], true, triangles);
    return TriangleMesh(std::move(vertices), std::move(triangles));
}

int cone_back_top_count(double top_radius, double edge, double sweep_degrees) {
    return std::max(2, static_cast<int>(std::lround(top_radius * sweep_degrees * std::numbers::pi / 180.0 / edge)) + 1);
}

TriangleMesh cloth_cone_back(double top_radius, double bottom_radius, double height, double edge, double sweep_degrees) {
    const double slant = std::hypot(bottom_radius - top_radius, height);
    const int count_rows = std::max(1, static_cast<int>(std::lround(slant / edge)));
    const double sweep = sweep_degrees * std::numbers::pi / 180.0;
    std::vector<glm::dvec3> vertices;
    std::vector<std::vector<std::uint32_t>> rows;
    for (int k = 0; k <= count_rows; ++k) {
        const double t = double(k) / count_rows;
        const double r = top_radius + (bottom_radius - top_radius) * t, y = -height * t;
        const int count = cone_back_top_count(r, edge, sweep_degrees);
        std::vector<std::uint32_t> row;
        for (int p = 0; p < count; ++p) {
            const double angle = -std::numbers::pi / 2.0 - sweep / 2.0 + sweep * p / (count - 1);  // round the back
            row.push_back(static_cast<std::uint32_t>(vertices.size()));
            vertices.emplace_back(r * std::cos(angle), y, r * std::sin(angle));
        }
        rows.push_back(std::move(row));
    }
    Triangles triangles;
    for (int k = 0; k < count_rows; ++k) zip_rows(rows[k], rows[k + 1], false, triangles);
    return TriangleMesh(std::move(vertices), std::move(triangles));
}

glm::dvec3 tabard_point(const TabardPattern& p, double x, double s) {
    const double r = p.yoke_radius, quarter = 0.5 * std::numbers::pi * r;
    if (std::abs(s) <= quarter) return {x, r * (std::cos(s / r) - 1.0), r * std::sin(s / r)};
    return {x, -r - (std::abs(s) - quarter), s > 0.0 ? r : -r};
}

TriangleMesh cloth_tabard(const TabardPattern& p) {
    // Stations across and along, so that the neck's sides and edges and the shoulder seam are rows and columns.
    std::vector<double> across, along;
    add_stations(across, -0.5 * p.width, -p.neck_half_width, p.edge);
    const std::size_t neck_left = across.size() - 1;
    add_stations(across, -p.neck_half_width, p.neck_half_width, p.edge);
    const std::size_t neck_right = across.size() - 1;
    add_stations(across, p.neck_half_width, 0.5 * p.width, p.edge);
    add_stations(along, -p.back_length, -p.neck_back, p.edge);
    const std::size_t neck_first = along.size() - 1;
    add_stations(along, -p.neck_back, 0.0, p.edge);
    add_stations(along, 0.0, p.neck_front, p.edge);
    const std::size_t neck_last = along.size() - 1;
    add_stations(along, p.neck_front, p.front_length, p.edge);

    // A row strictly inside the neck holds only the points either side of it.
    const auto in_neck = [&](std::size_t row, std::size_t column) {
        return row > neck_first && row < neck_last && column > neck_left && column < neck_right;
    };
    std::vector<glm::dvec3> vertices;
    std::vector<std::vector<std::uint32_t>> index(along.size(), std::vector<std::uint32_t>(across.size(), 0));
    for (std::size_t k = 0; k < along.size(); ++k) {
        for (std::size_t c = 0; c < across.size(); ++c) {
            if (in_neck(k, c)) continue;
            index[k][c] = static_cast<std::uint32_t>(vertices.size());
            vertices.push_back(tabard_point(p, across[c], along[k]));
        }
    }
    const auto part = [&](std::size_t row, std::size_t first, std::size_t last) {
        return std::vector<std::uint32_t>(index[row].begin() + static_cast<std::ptrdiff_t>(first),
                                          index[row].begin() + static_cast<std::ptrdiff_t>(last) + 1);
    };
    Triangles triangles;
    for (std::size_t k = 0; k + 1 < along.size(); ++k) {
        if (k + 1 <= neck_first || k >= neck_last) {
            zip_rows(index[k], index[k + 1], false, triangles);
        } else {  // the two shoulder straps either side of the neck
            zip_rows(part(k, 0, neck_left), part(k + 1, 0, neck_left), false, triangles);
            zip_rows(part(k, neck_right, across.size() - 1), part(k + 1, neck_right, across.size() - 1), false, triangles);
        }
    }
    return TriangleMesh(std::move(vertices), std::move(triangles));
}

}  // namespace clothsim
