// --frame-times: one CSV row per frame of the app, written as the frame ends and flushed, so that a script can
// follow a run while it goes (wait until the simulated time reaches a mark) and read afterwards what each
// frame cost and what it did to the cloth.
#pragma once

#include "clothsim/mass_spring.hpp"

#include <glm/vec3.hpp>

#include <filesystem>
#include <fstream>
#include <vector>

namespace clothsim {

// What a frame cost (wall milliseconds) and how many substeps it ran.
struct FrameCost {
    float frame_ms = 0.0f;   // since the previous frame's start
    float sim_ms = 0.0f;     // physics
    float render_ms = 0.0f;  // issuing the drawing
    long long substeps = 0;
};

// The columns: frame, frame_ms, simulation_ms, render_ms, substeps, then the cloth as the frame left it:
//   time            s: simulated time
//   max_move        m: the largest distance a particle moved since the previous row (0 on the first; nan when
//                   the particle count changed, a cloth rebuilt to another size)
//   max_speed       m/s: the largest particle speed (MassSpring::velocities)
//   mean_strain     the mean of |x_a - x_b| / L - 1 over the structural springs: how far the cloth is
//                   stretched on average (its sag under its weight, a stiffness change shows here first)
//   kinetic_energy  J
//   centroid_x/y/z  m: the mean particle position
class FrameLog {
public:
    // Creates or truncates `file` and writes the header; throws std::runtime_error naming the file when it
    // cannot be written.
    explicit FrameLog(const std::filesystem::path& file);
    // Appends the frame's row and flushes it; false once the file cannot be written (a full disk).
    bool write(const FrameCost& cost, const MassSpring& sim);

private:
    std::ofstream out_;
    long long frame_ = 0;
    std::vector<glm::vec3> previous_, current_;
};

}  // namespace clothsim
