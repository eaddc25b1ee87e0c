// Mesh files (clothsim/mesh_file.hpp): an OBJ file read into the triangles it describes; every bad file refused
// with one message naming the file and the line; a scene's mesh collider found beside the scene, then among the
// bundled meshes; a failed load keeping the scene it would have changed.
#include "clothsim/mesh_file.hpp"
#include "clothsim/mesh_shapes.hpp"
#include "clothsim/scene.hpp"
#include "temp_dir.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using namespace clothsim;

namespace {

using test::TempDir;

// Writes `text` to `name` in `dir`; returns its path.
fs::path write(const TempDir& dir, const std::string& name, const std::string& text) {
    std::ofstream(dir.path / name, std::ios::binary) << text;
    return dir.path / name;
}

// A unit square in the y = 0 plane, facing +y, as two triangles or as one quad.
const char* kSquare = "# a square\nv 0 0 0\nv 0 0 -1\nv 1 0 -1\nv 1 0 0\nf 1 4 3\nf 1 3 2\n";
const char* kQuad = "v 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nvn 0 1 0\nf 1//1 2//1 3//1 4//1\n";

}  // namespace

TEST_CASE("mesh file an OBJ file gives its vertices and its faces fanned into triangles", "[mesh_file]") {
    TempDir dir("mesh");
    const auto square = read_mesh_file(write(dir, "square.obj", kSquare));
    CHECK(square->vertices().size() == 4);
    CHECK(square->triangles().size() == 2);
    CHECK(square->face_normals()[0].y == Approx(1.0));
    const auto quad = read_mesh_file(write(dir, "quad.obj", kQuad));
    CHECK(quad->triangles().size() == 2);  // one quad, fanned
    CHECK(quad->face_normals()[0].y == Approx(1.0));
    // Negative indices count back from the last vertex.
    const auto relative = read_mesh_file(write(dir, "relative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"));
    CHECK(relative->triangles().size() == 1);
    CHECK(relative->face_normals()[0].z == Approx(1.0));
}

TEST_CASE("mesh file a bad file gets one message naming the file, and the line where there is one", "[mesh_file]") {
    TempDir dir("mesh");
    const std::string where = dir.path.string();
    CHECK_THROWS_WITH(read_mesh_file(dir.path / "missing.obj"),
                      Contains("cannot read mesh file '" + where + "/missing.obj'") && Contains("No such file"));
    CHECK_THROWS_WITH(read_mesh_file(dir.path), Contains("it is a directory"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "empty.obj", "")), Contains("empty.obj: no triangles (no 'f' lines)"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "points.obj", "v 0 0 0\nv 1 0 0\n")), Contains("no triangles"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n")),
                      Contains("nan.obj:2: a vertex needs three finite numbers; coordinate 2 is 'nan'"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "inf.obj", "v 0 0 0\nv 1 0 1e999\nv 0 1 0\nf 1 2 3\n")),
                      Contains("inf.obj:2:") && Contains("coordinate 3 is '1e999'"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "short.obj", "v 0 0\nf 1 1 1\n")),
                      Contains("short.obj:1: a vertex needs three finite numbers; coordinate 3 is ''"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n")),
                      Contains("range.obj:5: a face names vertex 4; 3 vertices are defined above it"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")),
                      Contains("zero.obj:4: a face's vertex is '0'"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n")),
                      Contains("two.obj:3: a face needs three or more vertices; it has 2"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "binary.obj", std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16))),
                      Contains("binary.obj: not a text file"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "scene.obj", "name = \"hanging\"\n[cloth]\nrows = 8\n")),
                      Contains("scene.obj: no triangles"));
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "far.obj", "v 0 0 0\nv 2e6 0 0\nv 0 1 0\nf 1 2 3\n")),
                      Contains("far.obj:2: coordinate 1 is 2e6; allowed: within +-1e6"));
    // A device streams without end: refused, not read.
    CHECK_THROWS_WITH(read_mesh_file("/dev/zero"), Contains("cannot read mesh file '/dev/zero': not a regular file"));
}

TEST_CASE("mesh file a claim of more triangles than allowed is refused before they are read", "[mesh_file]") {
    TempDir dir("mesh");
    // 2,000,001 triangles on three vertices, 12 bytes each: refused at the line that passes the limit.
    std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    text.reserve(text.size() + 12 * (kMaxMeshTriangles + 1));
    for (std::size_t k = 0; k <= kMaxMeshTriangles; ++k) text += "f 1 2 3\n";
    CHECK_THROWS_WITH(read_mesh_file(write(dir, "many.obj", text)),
                      Contains("many.obj:" + std::to_string(kMaxMeshTriangles + 4) + ": more than 2000000 triangles"));
    // A file larger than kMaxMeshFileBytes is refused by its size (sparse: no disk is used).
    const fs::path huge = dir.path / "huge.obj";
    std::ofstream(huge) << "v 0 0 0\n";
    fs::resize_file(huge, kMaxMeshFileBytes + 1);
    CHECK_THROWS_WITH(read_mesh_file(huge), Contains("huge.obj: the file has 268435457 bytes; allowed: at most 268435456 (256 MB)"));
}

TEST_CASE("mesh file a scene's mesh is found beside it, then among the bundled meshes, a bad one keeps the scene",
          "[mesh_file]") {
    TempDir dir("mesh");
    write(dir, "square.obj", kSquare);
    const std::string scene_text = "name = \"on a square\"\n[[colliders.shapes]]\nkind = \"mesh\"\nfile = \"square.obj\"\n"
                                   "position = [0.0, 0.5, 0.0]\nscale = 2.0\n";
    const fs::path scene_path = write(dir, "on-square.toml", scene_text);
    Scene scene = load_scene_file(scene_path);
    REQUIRE(scene.settings.colliders.shapes.size() == 1);
    const auto& mesh = std::get<MeshCollider>(scene.settings.colliders.shapes[0].shape);
    REQUIRE(mesh.mesh);
    CHECK(mesh.mesh->triangles().size() == 2);
    CHECK(mesh.scale == 2.0f);
    // Written back as given: the file name, not the mesh.
    CHECK_THAT(to_toml(scene), Contains("file = \"square.obj\""));
    // A bundled mesh by its name.
    const Scene bundled = parse_scene("[[colliders.shapes]]\nkind = \"mesh\"\nfile = \"round-table.obj\"\n", "test");
    CHECK(std::get<MeshCollider>(bundled.settings.colliders.shapes[0].shape).mesh->closed());
    // A missing or bad file names the scene's line and the mesh file's problem.
    write(dir, "bad.toml", "[[colliders.shapes]]\nkind = \"mesh\"\nfile = \"nowhere.obj\"\n");
    CHECK_THROWS_WITH(load_scene_file(dir.path / "bad.toml"),
                      Contains("bad.toml:3:") && Contains("colliders.shapes[0].file = \"nowhere.obj\": mesh file "
                                                          "'nowhere.obj' not found; looked in '" + dir.path.string()));
    write(dir, "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    write(dir, "bad2.toml", "[[colliders.shapes]]\nkind = \"mesh\"\nfile = \"nan.obj\"\n");
    CHECK_THROWS_WITH(load_scene_file(dir.path / "bad2.toml"), Contains("nan.obj:2: a vertex needs three finite numbers"));
    write(dir, "bad3.toml", "[[colliders.shapes]]\nkind = \"mesh\"\nposition = [0.0, 1.0, 0.0]\n");
    CHECK_THROWS_WITH(load_scene_file(dir.path / "bad3.toml"), Contains("colliders.shapes[0].file is missing"));
    // --set another file: read at once; a bad one changes nothing.
    const Scene before = scene;
    CHECK_THROWS_WITH(apply_override(scene, "colliders.shapes.0.file=" + (dir.path / "nan.obj").string()),
                      Contains("--set colliders.shapes.0.file=") && Contains("nan.obj:2:"));
    CHECK(scene.settings.colliders.shapes == before.settings.colliders.shapes);
    apply_override(scene, "colliders.shapes.0.file=round-table.obj");
    CHECK(std::get<MeshCollider>(scene.settings.colliders.shapes[0].shape).mesh->triangles().size() ==
          round_table().triangles().size());
}
