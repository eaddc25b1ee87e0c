// The surface of a torn cloth (cloth_surface.hpp): split along the tears, so that a cut shows as a seam
// and an opened tear as a crack, never as a missing row of cells, and no triangle spans a broken spring.
#include "split_obj.hpp"
#include "support.hpp"

#include "clothsim/cloth_mesh_shapes.hpp"
#include "clothsim/cloth_surface.hpp"
#include "clothsim/export.hpp"
#include "clothsim/scene.hpp"
#include "model/tearing.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

using namespace clothsim;

namespace {

constexpr int kSide = 8;
constexpr double kSpacing = 0.1;  // m: a 0.7 m square of 8 x 8

// A flat, free, weightless 8 x 8 cloth in the plane y = 1, rows along +z: u x v = -y.
MassSpring flat_cloth() {
    Scene s;
    s.cloth.rows = s.cloth.cols = kSide;
    s.cloth.size = {0.7f, 0.7f};
    s.cloth.origin = {0.0f, 1.0f, 0.0f};
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.0f, 0.0f, 1.0f};
    s.pins.preset = PinPreset::None;
    s.settings.forces.gravity = glm::vec3(0.0f);
    test::collider(s.settings.colliders, "ground").enabled = false;
    return build_simulation(s);
}

std::vector<glm::vec3> surface_vertices(const MassSpring& sim) {
    std::vector<glm::vec3> v = sim.positions();
    place_split_vertices(sim.surface(), v);
    return v;
}

double area(const std::vector<glm::vec3>& v, const std::array<std::uint32_t, 3>& t) {
    return 0.5 * glm::length(glm::cross(glm::dvec3(v[t[1]] - v[t[0]]), glm::dvec3(v[t[2]] - v[t[0]])));
}

// The piece of the cloth each surface vertex belongs to: a particle's own; an edge point's from-particle's;
// a centre's, that of its first corner.
std::vector<std::uint32_t> vertex_pieces(const MassSpring& sim) {
    std::vector<std::uint32_t> piece = connected_pieces(sim.topology(), sim.particle_count());
    const ClothSurface& s = sim.surface();
    for (const auto& e : s.edge_points) piece.push_back(piece[e.from]);
    for (const auto& c : s.centres) piece.push_back(piece[c.corner[0][0]]);
    return piece;
}

bool held(const Topology& t, std::uint32_t a, std::uint32_t b) {
    for (const Spring& s : t.springs) {
        if (s.kind != SpringKind::Bending && ((s.a == a && s.b == b) || (s.a == b && s.b == a))) return true;
    }
    return false;
}

// Every triangle lies in one piece and joins particles only along springs that hold.
void check_surface_respects_the_tears(const MassSpring& sim) {
    const ClothSurface& s = sim.surface();
    const std::vector<std::uint32_t> piece = vertex_pieces(sim);
    for (const auto& t : s.triangles) {
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = t[e], b = t[(e + 1) % 3];
            CHECK(piece[a] == piece[b]);
            if (a < s.particles && b < s.particles) CHECK(held(sim.topology(), a, b));
        }
    }
}

double piece_area(const MassSpring& sim, const std::vector<glm::vec3>& v, std::uint32_t label) {
    const std::vector<std::uint32_t> piece = vertex_pieces(sim);
    double sum = 0.0;
    for (const auto& t : sim.surface().triangles) sum += piece[t[0]] == label ? area(v, t) : 0.0;
    return sum;
}

// Cuts particle `lone` free and checks the surface keeps `patch` m^2 of cloth around it and `rest` for the piece of
// particle 0, the pieces' surfaces apart.
void check_cut_free(MassSpring& sim, std::uint32_t lone, double patch, double rest) {
    const glm::vec3 p = sim.position(lone);
    REQUIRE(sim.cut([&](glm::vec3 a, glm::vec3 b) { return (a == p) != (b == p); }) > 0);
    for (const Spring& sp : sim.topology().springs) CHECK((sp.a != lone && sp.b != lone));
    const std::vector<glm::vec3> v = surface_vertices(sim);
    const std::vector<std::uint32_t> piece = connected_pieces(sim.topology(), sim.particle_count());
    REQUIRE(piece[lone] != piece[0]);
    CHECK(piece_area(sim, v, piece[lone]) == Approx(patch).epsilon(1e-5));
    CHECK(piece_area(sim, v, piece[0]) == Approx(rest).epsilon(1e-5));
    check_surface_respects_the_tears(sim);
}

// The split surface's area; every triangle of it faces `facing` (+1 or -1) along y, as the cloth's own
// triangles on a flat cloth in a plane y = const.
double surface_area(const ClothSurface& s, const std::vector<glm::vec3>& v, float facing) {
    double total = 0.0;
    for (const auto& t : s.triangles) {
        total += area(v, t);
        const glm::vec3 n = glm::cross(v[t[1]] - v[t[0]], v[t[2]] - v[t[0]]);
        CHECK(facing * n.y > 0.0f);
    }
    return total;
}

// On a cloth cut while flat: the two ends of each broken edge have points of their own, which coincide (at the
// edge's middle). Returns how many such pairs there are.
std::size_t seam_pairs(const ClothSurface& s, const std::vector<glm::vec3>& v) {
    std::size_t pairs = 0;
    for (std::size_t i = 0; i < s.edge_points.size(); ++i) {
        for (std::size_t j = i + 1; j < s.edge_points.size(); ++j) {
            const auto &a = s.edge_points[i], &b = s.edge_points[j];
            if (a.whole || b.whole || a.from != b.to || a.to != b.from) continue;
            ++pairs;
            CHECK(glm::length(v[s.particles + i] - v[s.particles + j]) < 1e-6f);
            CHECK(glm::length(v[s.particles + i] - 0.5f * (v[a.from] + v[a.to])) < 1e-6f);
        }
    }
    return pairs;
}

// Within a piece nothing is split: the only vertices that coincide belong to different pieces (the two ends of a
// broken edge, the centres of a torn cell's pieces). A held edge's middle made twice, or a piece's corners each
// with a centre of their own, would coincide within one piece.
void check_coinciding_vertices_part(const MassSpring& sim, const std::vector<glm::vec3>& v) {
    const std::vector<std::uint32_t> piece = vertex_pieces(sim);
    for (std::size_t i = 0; i < v.size(); ++i) {
        for (std::size_t j = i + 1; j < v.size(); ++j) {
            if (glm::length(v[i] - v[j]) > 1e-6f) continue;
            INFO("vertices " << i << " and " << j << " coincide");
            CHECK(piece[i] != piece[j]);
        }
    }
}

// Cuts every spring that crosses the plane z = 0.35 (between rows 3 and 4).
std::size_t cut_between_rows_3_and_4(MassSpring& sim) {
    return sim.cut([](glm::vec3 a, glm::vec3 b) { return (a.z - 0.35f) * (b.z - 0.35f) < 0.0f; });
}

// A flat, free, weightless mesh cloth (cloth.mesh): the boundary-conforming disc of radius 0.35 m in 7 rings of
// 5 cm (cloth_mesh_shapes.hpp) in the plane y = 1, wound as the grid (normal -y).
MassSpring flat_disc_mesh(glm::vec3 gravity = glm::vec3(0.0f)) {
    Scene s;
    s.cloth.mesh = "disc.obj";
    s.cloth.mesh_data = std::make_shared<TriangleMesh>(cloth_disc(0.35, 7));
    s.cloth.origin = {0.0f, 1.0f, 0.0f};
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.0f, 0.0f, 1.0f};
    s.pins.preset = PinPreset::None;
    s.settings.forces.gravity = gravity;
    test::collider(s.settings.colliders, "ground").enabled = false;
    return build_simulation(s);
}

double triangles_area(const MassSpring& sim) {
    const std::vector<glm::vec3> v = sim.positions();
    double sum = 0.0;
    for (const auto& t : sim.topology().triangles) sum += area(v, t);
    return sum;
}

// Cuts every spring that crosses the plane z = 0.1213 (between vertices of the disc, off every one).
std::size_t cut_disc_chord(MassSpring& sim) {
    return sim.cut([](glm::vec3 a, glm::vec3 b) { return (a.z - 0.1213f) * (b.z - 0.1213f) < 0.0f; });
}

}  // namespace

TEST_CASE("cloth surface: an untorn cloth, square or disc, is drawn from the topology's triangles", "[tearing]") {
    const MassSpring square = flat_cloth();
    CHECK_FALSE(square.surface().split());
    CHECK(square.surface().vertex_count() == square.particle_count());
    const MassSpring disc = build_simulation(test::disc_specimen(15));
    CHECK_FALSE(disc.surface().split());
}

TEST_CASE("cloth surface: a straight cut through a flat cloth is a closed seam: the area stays, the split "
          "vertices meet, no triangle spans it", "[tearing]") {
    MassSpring sim = flat_cloth();
    const double whole = 0.7 * 0.7;
    REQUIRE(cut_between_rows_3_and_4(sim) > 0);
    const ClothSurface& s = sim.surface();
    REQUIRE(s.split());
    const std::vector<glm::vec3> v = surface_vertices(sim);
    REQUIRE(v.size() == s.vertex_count());
    // Counter-clockwise seen from u x v (-y), as the topology's triangles. Dropping the torn cells' triangles
    // would leave 0.7 x 0.1 m^2 out.
    CHECK(surface_area(s, v, -1.0f) == Approx(whole).epsilon(1e-5));
    CHECK(seam_pairs(s, v) == kSide);  // one per column: the vertical springs the cut crossed
    // The 7 torn cells of row 3: 8 x 2 ends of broken edges and 2 x 7 held edges' middles; two pieces each.
    CHECK(s.edge_points.size() == 30);
    CHECK(s.centres.size() == 14);
    check_coinciding_vertices_part(sim, v);
    check_surface_respects_the_tears(sim);
}

TEST_CASE("cloth surface: each side of a cut continues its own columns, however the other side moved",
          "[tearing]") {
    MassSpring sim = flat_cloth();
    REQUIRE(cut_between_rows_3_and_4(sim) > 0);
    const glm::vec3 moved(0.05f, 0.02f, 0.05f);  // the lower piece: across, up and away
    for (std::size_t i = 4 * kSide; i < sim.particle_count(); ++i) {
        sim.set_particle(i, sim.position(i) + moved, glm::vec3(0.0f));
    }
    const ClothSurface& s = sim.surface();
    const std::vector<glm::vec3> v = surface_vertices(sim);
    std::size_t ends = 0;
    for (std::size_t i = 0; i < s.edge_points.size(); ++i) {
        const ClothSurface::EdgePoint& e = s.edge_points[i];
        if (e.whole) continue;
        ++ends;
        // Half a spacing on along the column: +z below row 3, -z above row 4.
        const float along = e.from < 4 * kSide ? 0.05f : -0.05f;
        const glm::vec3 expected = sim.position(e.from) + glm::vec3(0.0f, 0.0f, along);
        INFO("the point of particle " << e.from << " towards " << e.to);
        CHECK(glm::length(v[s.particles + i] - expected) < 1e-6f);
    }
    CHECK(ends == 2 * kSide);
}

TEST_CASE("cloth surface: a torn cell whose four sides hold has its centre at the mean of its corners, on a "
          "bent cloth", "[tearing]") {
    MassSpring sim = flat_cloth();
    // Bent out of its plane, not affinely: y = 1 + 0.3 x^2 + 0.2 x z.
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const glm::vec3 p = sim.position(i);
        sim.set_particle(i, {p.x, 1.0f + 0.3f * p.x * p.x + 0.2f * p.x * p.z, p.z}, glm::vec3(0.0f));
    }
    // Cut the one diagonal (01, 10) of cell (3, 3): both the cell's triangles have it as an edge.
    const glm::vec3 a = sim.position(3 * kSide + 4), b = sim.position(4 * kSide + 3);
    REQUIRE(sim.cut([&](glm::vec3 p, glm::vec3 q) { return (p == a && q == b) || (p == b && q == a); }) > 0);
    const ClothSurface& s = sim.surface();
    REQUIRE(s.split());
    REQUIRE(s.centres.size() == 1);  // one piece: the four sides hold it together
    const std::vector<glm::vec3> v = surface_vertices(sim);
    const glm::vec3 mean = 0.25f * (sim.position(3 * kSide + 3) + sim.position(3 * kSide + 4) +
                                    sim.position(4 * kSide + 3) + sim.position(4 * kSide + 4));
    CHECK(glm::length(v[s.vertex_count() - 1] - mean) < 1e-6f);
    check_surface_respects_the_tears(sim);
}

TEST_CASE("cloth surface: a hand-made grid drawn without triangles stays so when a spring of it breaks",
          "[tearing]") {
    const MassSpring built = flat_cloth();
    Topology t = built.topology();
    t.triangles.clear();
    t.cell_triangles = false;
    MassSpring sim(t, built.state(), built.settings());
    REQUIRE(cut_between_rows_3_and_4(sim) > 0);
    CHECK_FALSE(sim.surface().split());  // no cell was whole to begin with: nothing is torn
}

TEST_CASE("cloth surface: the OBJ export of a topology that is no grid of its particles has faces without UVs",
          "[tearing]") {
    const MassSpring built = flat_cloth();
    Topology t = built.topology();
    t.rows = t.cols = 0;  // hand-made: the triangles stay, the grid is gone
    const MassSpring sim(t, built.state(), built.settings());
    const std::string path =
        (std::filesystem::temp_directory_path() / ("clothsim-nogrid-" + std::to_string(::getpid()) + ".obj")).string();
    std::string error;
    REQUIRE(write_obj(sim, path, error));
    std::ifstream in(path);
    std::size_t faces = 0, uvs = 0, vertices = 0;
    for (std::string line; std::getline(in, line);) {
        vertices += line.rfind("v ", 0) == 0 ? 1 : 0;
        uvs += line.rfind("vt ", 0) == 0 ? 1 : 0;
        if (line.rfind("f ", 0) == 0) {
            ++faces;
            CHECK(line.find('/') == std::string::npos);  // no reference to a UV that is not written
        }
    }
    in.close();
    std::filesystem::remove(path);
    CHECK(vertices == sim.particle_count());
    CHECK(uvs == 0);
    CHECK(faces == t.triangles.size());
}

TEST_CASE("cloth surface: an opened cut is a crack as wide as the pieces parted, each piece whole to the seam",
          "[tearing]") {
    MassSpring sim = flat_cloth();
    REQUIRE(cut_between_rows_3_and_4(sim) > 0);
    // The lower rows (4 to 7) moved 5 cm along +z, rigidly.
    const float parted = 0.05f;
    for (std::size_t i = 4 * kSide; i < sim.particle_count(); ++i) {
        sim.set_particle(i, sim.position(i) + glm::vec3(0.0f, 0.0f, parted), glm::vec3(0.0f));
    }
    const ClothSurface& s = sim.surface();
    const std::vector<glm::vec3> v = surface_vertices(sim);
    const std::vector<std::uint32_t> piece = connected_pieces(sim.topology(), sim.particle_count());
    REQUIRE(piece[0] != piece[sim.particle_count() - 1]);
    // Each piece reaches half a cell beyond its last row: rows 0 to 3 and a half, rows 3 and a half to 7.
    CHECK(piece_area(sim, v, piece[0]) == Approx(0.7 * 0.35).epsilon(1e-5));
    CHECK(piece_area(sim, v, piece[sim.particle_count() - 1]) == Approx(0.7 * 0.35).epsilon(1e-5));
    for (std::size_t i = 0; i < s.edge_points.size(); ++i) {
        for (std::size_t j = 0; j < s.edge_points.size(); ++j) {
            const auto &a = s.edge_points[i], &b = s.edge_points[j];
            if (a.whole || b.whole || a.from != b.to || a.to != b.from) continue;
            CHECK(glm::length(v[s.particles + i] - v[s.particles + j]) == Approx(parted).epsilon(1e-4));
        }
    }
    check_surface_respects_the_tears(sim);
}

TEST_CASE("cloth surface: a particle cut free keeps its own patch, one cell of cloth around it", "[tearing]") {
    MassSpring sim = flat_cloth();
    check_cut_free(sim, 3 * kSide + 3, kSpacing * kSpacing, 0.49 - kSpacing * kSpacing);
}

TEST_CASE("cloth surface: a tear pulled open keeps every triangle within one piece", "[tearing]") {
    MassSpring sim = test::pulled_apart(SolverMethod::Fast, 8.0f);  // it tears down the middle
    const std::uint64_t stamp = sim.topology_stamp();
    sim.run_steps(40);
    REQUIRE(sim.broken_springs() > 0);
    CHECK(sim.topology_stamp() != stamp);
    REQUIRE(sim.surface().split());
    const std::vector<glm::vec3> v = surface_vertices(sim);
    for (const glm::vec3& p : v) REQUIRE(std::isfinite(p.x + p.y + p.z));
    check_surface_respects_the_tears(sim);
    std::vector<glm::vec3> normals;
    split_surface_normals(sim.surface(), v, normals);
    REQUIRE(normals.size() == v.size());
    for (const glm::vec3& n : normals) CHECK(glm::length(n) == Approx(1.0f).epsilon(1e-5));
}

TEST_CASE("cloth surface: a mesh cloth cut along a chord is a closed seam, as the grid: the area stays, the ends "
          "of each broken edge meet, no triangle spans the cut", "[tearing]") {
    MassSpring sim = flat_disc_mesh();
    REQUIRE(sim.topology().mesh);
    const double whole = triangles_area(sim);
    // The side the mesh's triangles face (every one the same way on the flat disc).
    const std::vector<glm::vec3> rest = sim.positions();
    const auto& first = sim.topology().triangles.front();
    const float facing = glm::cross(rest[first[1]] - rest[first[0]], rest[first[2]] - rest[first[0]]).y > 0.0f ? 1.0f : -1.0f;
    const std::size_t springs = sim.topology().springs.size();
    REQUIRE(cut_disc_chord(sim) > 0);
    const std::size_t broken = springs - sim.topology().springs.size();
    REQUIRE(broken > 0);
    const ClothSurface& s = sim.surface();
    REQUIRE(s.split());
    CHECK(s.mesh);
    const std::vector<glm::vec3> v = surface_vertices(sim);
    REQUIRE(v.size() == s.vertex_count());
    const double total = surface_area(s, v, facing);  // wound as the mesh's own triangles
    // Dropping the triangles that lost an edge would leave a strip along the chord out; each torn triangle is
    // drawn as six triangles about its centroid, which tile it.
    CHECK(total == Approx(whole).epsilon(1e-5));
    CHECK(triangles_area(sim) < 0.95 * whole);
    CHECK(seam_pairs(s, v) == broken);
    check_coinciding_vertices_part(sim, v);
    check_surface_respects_the_tears(sim);
}

TEST_CASE("cloth surface: a mesh vertex cut free keeps its own patch, a third of each triangle around it", "[tearing]") {
    MassSpring sim = flat_disc_mesh();
    const std::uint32_t lone = 20;  // on ring 3 (vertices 19 .. 36)
    const std::vector<glm::vec3> before = sim.positions();
    double patch = 0.0;
    for (const auto& t : sim.topology().triangles) {
        if (t[0] == lone || t[1] == lone || t[2] == lone) patch += area(before, t) / 3.0;
    }
    check_cut_free(sim, lone, patch, triangles_area(sim) - patch);
}

TEST_CASE("cloth surface: a torn mesh cloth falling apart keeps every triangle within one piece, and its OBJ has "
          "a texture coordinate per vertex", "[tearing]") {
    MassSpring sim = flat_disc_mesh(glm::vec3(0.0f, -9.81f, 0.0f));
    sim.set_pinned(0, true);  // the centre
    REQUIRE(cut_disc_chord(sim) > 0);
    sim.run_steps(20);  // the cap beyond the chord falls about 0.5 m
    const ClothSurface& s = sim.surface();
    REQUIRE(s.split());
    const std::vector<glm::vec3> v = surface_vertices(sim);
    for (const glm::vec3& p : v) REQUIRE(std::isfinite(p.x + p.y + p.z));
    check_surface_respects_the_tears(sim);
    const std::vector<std::uint32_t> piece = vertex_pieces(sim);
    float gap = INFINITY;
    for (std::size_t i = 0; i < v.size(); ++i) {
        for (std::size_t j = 0; j < v.size(); ++j) {
            if (piece[i] != piece[j]) gap = std::min(gap, glm::length(v[i] - v[j]));
        }
    }
    CHECK(gap > 0.05f);  // the drawn pieces parted with the cloth's
    std::vector<glm::vec3> normals;
    split_surface_normals(s, v, normals);
    for (const glm::vec3& n : normals) CHECK(glm::length(n) == Approx(1.0f).epsilon(1e-5));
    // The OBJ: the split surface with a texture coordinate for every vertex, faces naming both.
    test::check_obj_is_the_split_surface(sim);
}
