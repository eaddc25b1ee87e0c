#include "frame_log.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace clothsim {

FrameLog::FrameLog(const std::filesystem::path& file) : out_(file, std::ios::trunc) {
    out_ << "frame,frame_ms,simulation_ms,render_ms,substeps,time,max_move,max_speed,mean_strain,kinetic_energy,"
            "centroid_x,centroid_y,centroid_z,broken_springs\n";
    out_.flush();
    if (!out_) throw std::runtime_error("cannot write " + file.string());
}

bool FrameLog::write(const FrameCost& cost, const MassSpring& sim) {
    sim.positions(current_);
    double max_move = 0.0;
    if (frame_ > 0 && previous_.size() != current_.size()) {
        max_move = std::nan("");
    } else if (frame_ > 0) {
        for (std::size_t i = 0; i < current_.size(); ++i) {
            max_move = std::max(max_move, double(glm::length(current_[i] - previous_[i])));
        }
    }
    double max_speed = 0.0;
    for (const glm::vec3& v : sim.velocities()) max_speed = std::max(max_speed, double(glm::length(v)));
    double strain = 0.0;
    std::size_t structural = 0;
    for (const Spring& s : sim.topology().springs) {
        if (s.kind != SpringKind::Structural || s.rest_length <= 0.0f) continue;
        strain += glm::length(current_[s.a] - current_[s.b]) / s.rest_length - 1.0;
        ++structural;
    }
    glm::dvec3 centroid(0.0);
    for (const glm::vec3& p : current_) centroid += glm::dvec3(p);
    if (!current_.empty()) centroid /= double(current_.size());

    ++frame_;
    char row[320];
    std::snprintf(row, sizeof row, "%lld,%.4f,%.4f,%.4f,%lld,%.6f,%.6g,%.6g,%.6g,%.6g,%.6f,%.6f,%.6f,%zu\n", frame_,
                  cost.frame_ms, cost.sim_ms, cost.render_ms, cost.substeps, sim.time(), max_move, max_speed,
                  structural ? strain / double(structural) : 0.0, sim.energy().kinetic, centroid.x, centroid.y,
                  centroid.z, sim.broken_springs());
    out_ << row;
    out_.flush();
    std::swap(previous_, current_);
    return bool(out_);
}

}  // namespace clothsim
