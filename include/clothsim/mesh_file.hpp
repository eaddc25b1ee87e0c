// Reading a triangle mesh from a Wavefront OBJ file, for mesh colliders (shapes/mesh.hpp). Parsed by
// tinyobjloader (Debian's libtinyobjloader-dev, double precision: polygons fanned into triangles, negative
// indices, v/vt/vn faces); checked first line by line here, so a bad file is refused naming its line.
#pragma once

#include "clothsim/triangle_mesh.hpp"

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

namespace clothsim {

// The largest OBJ file read: 256 MB (about 2.5 million triangles of short indices; kMaxMeshTriangles bounds
// what is kept).
inline constexpr std::uintmax_t kMaxMeshFileBytes = 256ull << 20;

// The mesh in `path`. Throws SceneError naming the file, and the line where there is one: a file that is
// missing, unreadable, a directory or not a regular file, larger than kMaxMeshFileBytes or not text; a vertex
// without three finite numbers, or beyond kMaxMeshCoordinate; a face with fewer than three vertices or an
// index out of range; no triangles; more than kMaxMeshTriangles.
std::shared_ptr<const TriangleMesh> read_mesh_file(const std::filesystem::path& path);
// The same from the file's text, `name` in the messages.
std::shared_ptr<const TriangleMesh> parse_mesh_text(std::string_view text, const std::string& name);

// Writes `mesh` as OBJ (v and f lines), `comment` first as # lines. Throws SceneError.
void write_mesh_file(const TriangleMesh& mesh, const std::filesystem::path& path, std::string_view comment);

// Where a mesh collider's `file` is: as given when absolute; else in `scene_directory` (the scene file's
// folder; empty: the working directory), then among the bundled meshes (mesh_directory()). Throws
// SceneError listing the places tried.
std::filesystem::path find_mesh_file(std::string_view file, const std::filesystem::path& scene_directory);

// The folder a scene's mesh files are looked for in first: the directory of `scene_source` when it names a
// scene file, else none (the working directory: a bundled scene, --set, a scene from text).
std::filesystem::path scene_file_directory(std::string_view scene_source);

// Reads the mesh a mesh collider's `file` names (find_mesh_file) into `collider.mesh`; throws SceneError.
struct MeshCollider;
void load_collider_mesh(MeshCollider& collider, const std::filesystem::path& scene_directory);

// Reads the OBJ file cloth.mesh names (found as a mesh collider's file is) into cloth.mesh_data, refused with
// the reason when it cannot be a cloth (cloth_mesh.hpp: cloth_mesh_problem); "" clears it. Throws SceneError.
struct ClothSettings;
void load_cloth_mesh(ClothSettings& cloth, const std::filesystem::path& scene_directory);

// $CLOTHSIM_MESHES, else share/clothsim/meshes (data_dirs.hpp).
std::filesystem::path mesh_directory();

}  // namespace clothsim
