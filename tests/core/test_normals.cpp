// Vertex normals: area-weighted sums of the triangles' cross products, by the triangle list or, on a full
// grid, by the row sweep (every kernel), which must give the list's bit for bit.
#include "every_kernel.hpp"
#include "support.hpp"

#include "clothsim/normals.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstring>
#include <utility>

using namespace clothsim;

TEST_CASE("normals: a flat cloth's are u x v, a folded one's average by area", "[normals]") {
    Scene s;
    s.cloth.rows = 4;
    s.cloth.cols = 5;
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.0f, 0.0f, 1.0f};
    MassSpring sim = build_simulation(s);
    std::vector<glm::vec3> normals;
    compute_vertex_normals(sim.topology(), sim.state().position, normals);
    REQUIRE(normals.size() == sim.particle_count());
    for (const glm::vec3& n : normals) CHECK(n.y == Approx(-1.0f));

    // A 2 x 3 strip folded 90 degrees along its middle column. Vertex 1 touches two triangles of the flat
    // face (normal -y) and one of the folded face (normal -x): by area, (-1, -2) / sqrt(5); vertex 4 the
    // reverse.
    Topology t;
    t.rows = 2;
    t.cols = 3;
    t.triangles = {{0, 1, 3}, {1, 4, 3}, {1, 2, 4}, {2, 5, 4}};
    DVec3Array p;
    p.resize(6);
    p.set(0, {-1, 0, 0}), p.set(1, {0, 0, 0}), p.set(2, {0, -1, 0});
    p.set(3, {-1, 0, 1}), p.set(4, {0, 0, 1}), p.set(5, {0, -1, 1});
    compute_vertex_normals(t, p, normals);
    CHECK(normals[0].y == Approx(-1.0f));
    CHECK(normals[2].x == Approx(-1.0f));
    CHECK(normals[1].x == Approx(-1.0f / std::sqrt(5.0f)));
    CHECK(normals[1].y == Approx(-2.0f / std::sqrt(5.0f)));
    CHECK(normals[4].x == Approx(-2.0f / std::sqrt(5.0f)));
    CHECK(normals[4].y == Approx(-1.0f / std::sqrt(5.0f)));
    // A chain has no triangles: a fixed, finite normal.
    Topology chain;
    compute_vertex_normals(chain, p, normals);
    CHECK(normals[3] == glm::vec3(0.0f, 1.0f, 0.0f));
}

TEST_CASE("normals: the grid sweep gives the triangle list's normals bit for bit, with every kernel, threaded or not, "
          "degenerate and NaN vertices included",
          "[normals]") {
    for (int n : {2, 3, 17, 130, 260}) {
        Scene s;
        s.cloth.rows = n;
        s.cloth.cols = n + 3;
        MassSpring sim = build_simulation(s);
        REQUIRE(sim.topology().cell_triangles);
        // A crumpled cloth: every vertex moved by a different amount, so no two normals agree by symmetry.
        DVec3Array p = sim.state().position;
        for (std::size_t i = 0; i < p.size(); ++i) {
            const double t = static_cast<double>(i);
            p.add(i, {0.05 * std::sin(0.7 * t), 0.05 * std::cos(1.3 * t), 0.03 * std::sin(2.1 * t + 0.4)});
        }
        const int cols = n + 3;
        if (n >= 17) {
            // A patch of rows 2-5 and columns 3-12 gathered into one point: its inner vertices have no area
            // around them and take the fixed up normal. And NaN particles: their own and their neighbours'
            // normals are not finite sums, and take the up normal too. One lies in the vector loop's body, one
            // in its last columns (the tail), one on the top row and one on the last column (the scalar sums).
            for (int r = 2; r <= 5; ++r) {
                for (int c = 3; c <= 12; ++c) p.set(static_cast<std::size_t>(r * cols + c), {0.1, 0.2, 0.3});
            }
            for (const auto& [r, c] : {std::pair{9, 9}, {12, cols - 3}, {0, 5}, {7, cols - 1}}) {
                p.set(static_cast<std::size_t>(r * cols + c), {std::nan(""), 0.0, 0.0});
            }
        }
        Topology list = sim.topology();
        list.cell_triangles = false;  // the same triangles, summed by walking the list
        std::vector<glm::vec3> list_normals;
        compute_vertex_normals(list, p, list_normals);
        if (n >= 17) {
            for (const auto& [r, c] : {std::pair{3, 5}, {9, 10}, {12, cols - 2}, {1, 5}, {8, cols - 1}}) {
                INFO("vertex " << r << ", " << c);
                REQUIRE(list_normals[static_cast<std::size_t>(r * cols + c)] == glm::vec3(0.0f, 1.0f, 0.0f));
            }
        }
        test::with_every_kernel([&] {
            std::vector<glm::vec3> grid_normals;
            compute_vertex_normals(sim.topology(), p, grid_normals);
            INFO(n << " x " << n + 3 << ", the " << FastSolver::kernel_name() << " kernel");
            REQUIRE(grid_normals.size() == list_normals.size());
            // Bitwise: == would call a NaN normal unequal to itself (neither path makes one).
            CHECK(std::memcmp(grid_normals.data(), list_normals.data(), grid_normals.size() * sizeof(glm::vec3)) == 0);
        });
    }
    // A disc leaves cells out: it is no full grid and takes the list.
    Scene disc;
    disc.cloth.shape = ClothShape::Disc;
    CHECK_FALSE(build_simulation(disc).topology().cell_triangles);
}
