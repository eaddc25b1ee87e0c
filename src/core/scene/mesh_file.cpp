#include "clothsim/mesh_file.hpp"

#include "clothsim/cloth_mesh.hpp"

#include "clothsim/collider.hpp"
#include "clothsim/data_dirs.hpp"
#include "clothsim/scene.hpp"

#include <tiny_obj_loader.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {
namespace {

// Skips spaces and tabs; returns the next token (up to a space, tab or end).
std::string_view next_token(std::string_view& rest) {
    std::size_t start = rest.find_first_not_of(" \t\r");
    if (start == std::string_view::npos) {
        rest = {};
        return {};
    }
    rest.remove_prefix(start);
    const std::size_t end = std::min(rest.find_first_of(" \t\r"), rest.size());
    const std::string_view token = rest.substr(0, end);
    rest.remove_prefix(end);
    return token;
}

// The checks tinyobjloader does not make, or makes without the line (docs/SCENE_FILES.md, "Mesh files"):
// every `v` has three finite numbers, every `f` three or more vertices with indices in range. Returns the
// triangles the faces make once fanned.
std::size_t check_lines(std::string_view text, const std::string& name) {
    std::size_t vertices = 0, triangles = 0, line_number = 0;
    auto fail = [&](const std::string& why) { throw SceneError(name + ":" + std::to_string(line_number) + ": " + why); };
    while (!text.empty()) {
        ++line_number;
        const std::size_t end = std::min(text.find('\n'), text.size());
        std::string_view line = text.substr(0, end);
        text.remove_prefix(std::min(end + 1, text.size()));
        const std::string_view command = next_token(line);
        if (command == "v") {
            for (int k = 0; k < 3; ++k) {
                const std::string token(next_token(line));
                char* stop = nullptr;
                errno = 0;
                const double value = token.empty() ? NAN : std::strtod(token.c_str(), &stop);
                if (token.empty() || stop != token.c_str() + token.size() || !std::isfinite(value)) {
                    fail("a vertex needs three finite numbers; coordinate " + std::to_string(k + 1) + " is '" + token + "'");
                }
                if (std::fabs(value) > kMaxMeshCoordinate) {
                    fail("coordinate " + std::to_string(k + 1) + " is " + token + "; allowed: within +-1e6 (mesh units)");
                }
            }
            ++vertices;
        } else if (command == "f") {
            std::size_t corners = 0;
            for (std::string_view token = next_token(line); !token.empty(); token = next_token(line)) {
                const std::string_view index_text = token.substr(0, token.find('/'));
                long long index = 0;
                const auto parsed = std::from_chars(index_text.data(), index_text.data() + index_text.size(), index);
                if (parsed.ec != std::errc() || parsed.ptr != index_text.data() + index_text.size() || index == 0) {
                    fail("a face's vertex is '" + std::string(token) + "'; allowed: an index from 1 (or from -1 back)");
                }
                const long long resolved = index > 0 ? index : static_cast<long long>(vertices) + index + 1;
                if (resolved < 1 || resolved > static_cast<long long>(vertices)) {
                    fail("a face names vertex " + std::string(index_text) + "; " + std::to_string(vertices) +
                         " vertices are defined above it");
                }
                ++corners;
            }
            if (corners < 3) fail("a face needs three or more vertices; it has " + std::to_string(corners));
            triangles += corners - 2;
            if (triangles > kMaxMeshTriangles) {
                fail("more than " + std::to_string(kMaxMeshTriangles) + " triangles; allowed: at most that many");
            }
        }
    }
    if (triangles == 0) {
        throw SceneError(name + ": no triangles (no 'f' lines); allowed: a Wavefront OBJ file with faces");
    }
    return triangles;
}

}  // namespace

std::shared_ptr<const TriangleMesh> read_mesh_file(const std::filesystem::path& path) {
    const std::string name = path.string();
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw SceneError("cannot read mesh file '" + name + "': it is a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw SceneError("cannot read mesh file '" + name + "': " + std::strerror(errno));
    // A device or a pipe could stream without end: only regular files are read.
    if (!std::filesystem::is_regular_file(path, ec)) {
        throw SceneError("cannot read mesh file '" + name + "': not a regular file");
    }
    const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
    if (!ec && bytes > kMaxMeshFileBytes) {
        throw SceneError(name + ": the file has " + std::to_string(bytes) + " bytes; allowed: at most " +
                         std::to_string(kMaxMeshFileBytes) + " (" + std::to_string(kMaxMeshFileBytes >> 20) + " MB)");
    }
    // At most one byte past the limit is read, however the file grows meanwhile.
    std::string text(static_cast<std::size_t>(std::min<std::uintmax_t>(ec ? 0 : bytes, kMaxMeshFileBytes)), '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (in.bad()) throw SceneError("cannot read mesh file '" + name + "'");
    if (in.peek() != std::char_traits<char>::eof()) {
        throw SceneError(name + ": the file has more than " + std::to_string(kMaxMeshFileBytes) + " bytes");
    }
    return parse_mesh_text(text, name);
}

std::shared_ptr<const TriangleMesh> parse_mesh_text(std::string_view text, const std::string& name) {
    if (text.size() > kMaxMeshFileBytes) {
        throw SceneError(name + ": the file has more than " + std::to_string(kMaxMeshFileBytes) + " bytes");
    }
    if (text.find('\0') != std::string_view::npos) {
        throw SceneError(name + ": not a text file; allowed: a Wavefront OBJ file");
    }
    const std::size_t expected = check_lines(text, name);
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warning, error;
    std::istringstream stream{std::string(text)};
    // Materials are not read (the renderer draws every collider in its own look).
    std::istringstream empty;
    tinyobj::MaterialStreamReader none(empty);
    if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warning, &error, &stream, &none, true)) {
        throw SceneError(name + ": " + (error.empty() ? std::string("not a Wavefront OBJ file") : error));
    }
    std::vector<glm::dvec3> vertices(attrib.vertices.size() / 3);
    for (std::size_t i = 0; i < vertices.size(); ++i) {
        vertices[i] = {attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]};
    }
    std::vector<TriangleMesh::Triangle> triangles;
    triangles.reserve(expected);
    for (const tinyobj::shape_t& shape : shapes) {
        const std::vector<tinyobj::index_t>& indices = shape.mesh.indices;
        for (std::size_t k = 0; k + 2 < indices.size(); k += 3) {
            triangles.push_back({static_cast<std::uint32_t>(indices[k].vertex_index),
                                 static_cast<std::uint32_t>(indices[k + 1].vertex_index),
                                 static_cast<std::uint32_t>(indices[k + 2].vertex_index)});
        }
    }
    try {
        return std::make_shared<const TriangleMesh>(std::move(vertices), std::move(triangles));
    } catch (const std::invalid_argument& e) {
        throw SceneError(name + ": " + e.what());
    }
}

std::filesystem::path scene_file_directory(std::string_view scene_source) {
    std::error_code ec;
    const std::filesystem::path source(scene_source);
    return std::filesystem::is_regular_file(source, ec) ? source.parent_path() : std::filesystem::path();
}

void load_cloth_mesh(ClothSettings& cloth, const std::filesystem::path& scene_directory) {
    if (cloth.mesh.empty()) {
        cloth.mesh_data.reset();
        return;
    }
    const std::filesystem::path path = find_mesh_file(cloth.mesh, scene_directory);
    std::shared_ptr<const TriangleMesh> mesh = read_mesh_file(path);
    if (const std::string problem = cloth_mesh_problem(mesh->vertices(), mesh->triangles()); !problem.empty()) {
        throw SceneError(path.string() + " cannot be a cloth: " + problem);
    }
    cloth.mesh_data = std::move(mesh);
}

void load_collider_mesh(MeshCollider& collider, const std::filesystem::path& scene_directory) {
    collider.mesh = read_mesh_file(find_mesh_file(collider.file, scene_directory));
}

void write_mesh_file(const TriangleMesh& mesh, const std::filesystem::path& path, std::string_view comment) {
    std::ofstream out(path, std::ios::binary);
    if (!out) throw SceneError("cannot write mesh file '" + path.string() + "': " + std::strerror(errno));
    std::string text;
    for (std::string_view rest = comment; !rest.empty();) {
        const std::size_t end = std::min(rest.find('\n'), rest.size());
        text += "# " + std::string(rest.substr(0, end)) + "\n";
        rest.remove_prefix(std::min(end + 1, rest.size()));
    }
    char line[128];
    for (const glm::dvec3& v : mesh.vertices()) {
        std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", v.x, v.y, v.z);
        text += line;
    }
    for (const TriangleMesh::Triangle& t : mesh.triangles()) {
        std::snprintf(line, sizeof line, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
        text += line;
    }
    out << text;
    if (!out) throw SceneError("cannot write mesh file '" + path.string() + "'");
}

std::filesystem::path mesh_directory() { return data_directory("CLOTHSIM_MESHES", "meshes"); }

std::filesystem::path find_mesh_file(std::string_view file, const std::filesystem::path& scene_directory) {
    if (file.empty()) throw SceneError("no mesh file named; allowed: the path of a Wavefront OBJ file");
    const std::filesystem::path given(file);
    std::error_code ec;
    if (given.is_absolute()) return given;
    const std::filesystem::path beside = scene_directory.empty() ? given : scene_directory / given;
    if (std::filesystem::exists(beside, ec)) return beside;
    const std::filesystem::path bundled = mesh_directory() / given;
    if (std::filesystem::exists(bundled, ec)) return bundled;
    throw SceneError("mesh file '" + std::string(file) + "' not found; looked in " +
                     (scene_directory.empty() ? std::string("the working directory") : "'" + scene_directory.string() + "'") +
                     " and among the bundled meshes in '" + mesh_directory().string() + "'");
}

}  // namespace clothsim
