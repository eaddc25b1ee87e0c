// Writing simulation results to files: the final mesh as Wavefront OBJ, positions over time as CSV.
#pragma once

#include "clothsim/mass_spring.hpp"

#include <fstream>
#include <string>

namespace clothsim {

// Writes positions, per-vertex UVs and the cloth's triangles; a torn cloth split along its tears (cloth_surface.hpp).
// With `colliders`, the cloth is object `cloth` and each enabled collider with a surface follows as its own
// object, `collider-N-<kind>` (mesh_shapes.hpp: collider_surface). Returns false (with `error` set) on failure.
bool write_obj(const MassSpring& sim, const std::string& path, std::string& error, bool colliders = false);

// CSV with header `step,time,particle,x,y,z`, one row per particle per recorded step.
class TrajectoryWriter {
public:
    // Opens (truncates) the file and writes the header; check ok() / error().
    explicit TrajectoryWriter(const std::string& path);
    bool ok() const { return ok_; }
    const std::string& error() const { return error_; }
    void record(long long step, const MassSpring& sim);
    bool finish();  // flushes and closes; false if anything failed to write

private:
    std::ofstream out_;
    std::string path_;
    std::string error_;
    bool ok_ = false;
};

}  // namespace clothsim
