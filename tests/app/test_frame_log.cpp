// The app's --frame-times log: each row has the frame's costs and the cloth as the frame left it, measured the
// way a reader of the file would measure it from the positions.
#include "frame_log.hpp"

#include "app/run_process.hpp"

#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>

#include <glm/geometric.hpp>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace clothsim;
using clothsim::test::TempDir;
using Catch::Matchers::Contains;

namespace {

std::vector<std::vector<double>> rows_of(const std::filesystem::path& file) {
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    CHECK(line == "frame,frame_ms,simulation_ms,render_ms,substeps,time,max_move,max_speed,mean_strain,kinetic_energy,"
                  "centroid_x,centroid_y,centroid_z,broken_springs");
    std::vector<std::vector<double>> rows;
    while (std::getline(in, line)) {
        std::vector<double> v;
        std::stringstream fields(line);
        for (std::string f; std::getline(fields, f, ',');) v.push_back(std::strtod(f.c_str(), nullptr));
        rows.push_back(v);
    }
    return rows;
}

}  // namespace

TEST_CASE("frame log: each row is written as the frame ends, with how far the cloth moved, its speed, strain and centroid") {
    const TempDir dir("frame_log");
    Scene scene = load_scene("hanging");
    scene.cloth.rows = scene.cloth.cols = 8;
    MassSpring sim = build_simulation(scene);
    FrameLog log(dir / "frames.csv");
    REQUIRE(log.write({16.5f, 4.25f, 2.0f, 0}, sim));
    CHECK(rows_of(dir / "frames.csv").size() == 1);  // there before the next frame: flushed
    const std::vector<glm::vec3> before = sim.positions();
    sim.run_steps(3);
    REQUIRE(log.write({17.0f, 5.0f, 2.5f, 3LL * sim.settings().integration.substeps}, sim));

    const std::vector<std::vector<double>> rows = rows_of(dir / "frames.csv");
    REQUIRE(rows.size() == 2);
    REQUIRE(rows[1].size() == 14);
    CHECK(rows[0][0] == 1);
    CHECK(rows[0][1] == 16.5);
    CHECK(rows[0][6] == 0.0);  // nothing to compare the first row with
    CHECK(rows[1][0] == 2);
    CHECK(rows[1][4] == 3 * sim.settings().integration.substeps);
    CHECK(rows[1][5] == Approx(3 * sim.settings().integration.dt));
    double moved = 0.0, fastest = 0.0, strain = 0.0;
    glm::dvec3 centroid(0.0);
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        moved = std::max(moved, double(glm::length(sim.position(i) - before[i])));
        centroid += glm::dvec3(sim.position(i)) / double(sim.particle_count());
    }
    for (const glm::vec3& v : sim.velocities()) fastest = std::max(fastest, double(glm::length(v)));
    int structural = 0;
    for (const Spring& s : sim.topology().springs) {
        if (s.kind != SpringKind::Structural) continue;
        strain += glm::length(sim.position(s.a) - sim.position(s.b)) / s.rest_length - 1.0;
        ++structural;
    }
    CHECK(moved > 0.0);
    CHECK(rows[1][6] == Approx(moved).epsilon(1e-5));
    CHECK(rows[1][7] == Approx(fastest).epsilon(1e-5));
    CHECK(rows[1][8] == Approx(strain / structural).epsilon(1e-4));
    CHECK(rows[1][9] == Approx(sim.energy().kinetic).epsilon(1e-5));
    CHECK(rows[1][11] == Approx(centroid.y).margin(1e-6));
    CHECK(rows[1][13] == double(sim.broken_springs()));

    // A cloth rebuilt to another size: the move cannot be measured, and the row says so.
    scene.cloth.rows = 9;
    REQUIRE(log.write({}, build_simulation(scene)));
    CHECK(std::isnan(rows_of(dir / "frames.csv")[2][6]));
}

TEST_CASE("frame log: a file that cannot be written is refused by name") {
    const TempDir dir("frame_log_refused");
    CHECK_THROWS_WITH(FrameLog(dir / "no-such-folder" / "frames.csv"), Contains("no-such-folder/frames.csv"));
}
