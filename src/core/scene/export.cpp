#include "clothsim/export.hpp"

#include "clothsim/atomic_file.hpp"
#include "clothsim/mesh_shapes.hpp"

#include <cerrno>
#include <cstring>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace clothsim {

bool write_obj(const MassSpring& sim, const std::string& path, std::string& error, bool colliders) {
    std::ostringstream out;
    const Topology& t = sim.topology();
    if (t.mesh) {
        out << "# clothsim mesh: a mesh cloth of " << sim.particle_count() << " particles, t = " << sim.time() << " s\n";
    } else {
        out << "# clothsim mesh: " << t.rows << " x " << t.cols << " particles, t = " << sim.time() << " s\n";
    }
    out.precision(9);
    if (colliders) out << "o cloth\n";
    // A torn cloth is written split along its tears (cloth_surface.hpp): its split vertices follow the particles.
    const ClothSurface& surface = sim.surface();
    std::vector<glm::vec3> vertices = sim.positions();
    if (surface.split()) place_split_vertices(surface, vertices);
    for (const glm::vec3& p : vertices) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    auto uv = [&](glm::vec2 grid) {  // grid: (column, row)
        const glm::vec2 texture = grid_uv(t, grid);
        out << "vt " << texture.x << ' ' << texture.y << '\n';
    };
    // UVs come from the grid: a topology that is not a grid of its particles is written without them.
    // A mesh cloth's are its own (metres of cloth, Topology::uv).
    const bool grid = t.mesh || static_cast<std::size_t>(t.rows) * static_cast<std::size_t>(t.cols) == sim.particle_count();
    if (t.mesh) {
        for (const glm::vec2& texture : t.uv) out << "vt " << texture.x << ' ' << texture.y << '\n';
        for (const glm::vec2& texture : surface.split_place) out << "vt " << texture.x << ' ' << texture.y << '\n';
    } else if (grid) {
        for (int r = 0; r < t.rows; ++r) {
            for (int c = 0; c < t.cols; ++c) uv(glm::vec2(float(c), float(r)));
        }
        for (const glm::vec2& place : surface.split_place) uv(place);
    }
    auto corner = [&](std::uint32_t v) {
        out << ' ' << v + 1;
        if (grid) out << '/' << v + 1;
    };
    for (const auto& tri : surface.split() ? surface.triangles : t.triangles) {
        out << 'f';
        for (std::uint32_t v : tri) corner(v);
        out << '\n';
    }
    if (colliders) {
        // Each collider after the cloth: its vertices continue the file's numbering; no texture coordinates.
        std::size_t first = vertices.size() + 1;
        const std::vector<Collider>& shapes = sim.colliders();
        for (std::size_t i = 0; i < shapes.size(); ++i) {
            if (!shapes[i].enabled) continue;
            std::optional<TriangleMesh> mesh;
            try {
                mesh = collider_surface(shapes[i]);
            } catch (const std::invalid_argument&) {
                continue;  // no area to write (a cylinder of radius 0)
            }
            if (!mesh) continue;
            out << "o collider-" << i << '-' << kind_name(shapes[i]) << '\n';
            for (const glm::dvec3& p : mesh->vertices()) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
            for (const TriangleMesh::Triangle& tri : mesh->triangles()) {
                out << "f " << tri[0] + first << ' ' << tri[1] + first << ' ' << tri[2] + first << '\n';
            }
            first += mesh->vertices().size();
        }
    }
    if (!write_file_atomically(path, out.str(), error)) {
        error = "OBJ file: " + error;
        return false;
    }
    return true;
}

TrajectoryWriter::TrajectoryWriter(const std::string& path) : out_(path), path_(path) {
    if (!out_) {
        error_ = "cannot write trajectory file '" + path + "': " + std::strerror(errno);
        return;
    }
    out_.precision(9);
    out_ << "step,time,particle,x,y,z\n";
    ok_ = static_cast<bool>(out_);
}

void TrajectoryWriter::record(long long step, const MassSpring& sim) {
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const glm::vec3 p = sim.position(i);
        out_ << step << ',' << sim.time() << ',' << i << ',' << p.x << ',' << p.y << ',' << p.z << '\n';
    }
}

bool TrajectoryWriter::finish() {
    errno = 0;
    out_.close();
    if (!out_) {
        error_ = "failed while writing trajectory file '" + path_ + "'" + (errno ? std::string(": ") + std::strerror(errno) : "");
        return false;
    }
    return true;
}

}  // namespace clothsim
