#include "clothsim/export.hpp"

#include <cerrno>
#include <cstring>

namespace clothsim {

bool write_obj(const MassSpring& sim, const std::string& path, std::string& error) {
    std::ofstream out(path);
    if (!out) {
        error = "cannot write OBJ file '" + path + "': " + std::strerror(errno);
        return false;
    }
    const Topology& t = sim.topology();
    out << "# clothsim mesh: " << t.rows << " x " << t.cols << " particles, t = " << sim.time() << " s\n";
    out.precision(9);
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const glm::vec3 p = sim.position(i);
        out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    }
    for (int r = 0; r < t.rows; ++r) {
        for (int c = 0; c < t.cols; ++c) {
            out << "vt " << (t.cols > 1 ? float(c) / float(t.cols - 1) : 0.0f) << ' '
                << (t.rows > 1 ? 1.0f - float(r) / float(t.rows - 1) : 0.0f) << '\n';
        }
    }
    for (const auto& tri : t.triangles) {
        out << "f " << tri[0] + 1 << '/' << tri[0] + 1 << ' ' << tri[1] + 1 << '/' << tri[1] + 1 << ' '
            << tri[2] + 1 << '/' << tri[2] + 1 << '\n';
    }
    out.close();
    if (!out) {
        error = "failed while writing OBJ file '" + path + "'";
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
    out_.close();
    if (!out_) {
        error_ = "failed while writing trajectory file '" + path_ + "'";
        return false;
    }
    return true;
}

}  // namespace clothsim
