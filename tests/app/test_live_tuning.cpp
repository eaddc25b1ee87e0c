// Live tuning on every bundled scene, as a user does it: the app started with the scene, running; at 0.5 s the
// wind typed 6 m/s stronger and back, the damping typed to 10x and 0.1x and reset with its button, then the
// stretch slider dragged to 10x and to 0.1x. The app's --frame-times log (frame_log.hpp: simulated time, how far any
// particle moved, the fastest speed, the mean strain and the centroid, one row per frame, written as it runs)
// says what each change did: the session waits on its simulated time, never on the wall clock.
//
// What must hold on every scene: no frame moves a particle further than the fastest speed seen could carry it
// in that frame (a restart or a rebuild puts the cloth back at its start: a jump), no message on stderr (the
// guard, a pause, a failed rebuild), and the document keeps the values set. What each change must do to the
// cloth, where the physics says it shows (the issue asks for 2 simulated seconds; the stretch shows in 1;
// measured ratios of the second strain to the first: 13 on pile to 148 on tear):
//   stretch       the mean strain of the structural springs, averaged over the second after each drag, is
//                 lower at 10x than before, and at 0.1x at least 3 times what it was at 10x
//   wind +6 m/s   along +x: within 2 s the centroid moves at least 3 mm along +x
// The exceptions, from the physics: `falling` lies asleep and flat on the ground (no strain to change; wind
// parallel to a flat cloth exerts no force in the triangle wind model, drag on each triangle along its normal,
// docs/SCENE_FILES.md), as does `pile` for the wind; `tear` lies slack once its gusts have ripped it free; and
// `skirt` stands for the mesh cloths (`cape` is the same code on another mesh, and each costs 90 s here on the list
// path); `stiff-drape`'s XPBD (32 substeps of one iteration) is iteration-bound: its strain, 3.0e-3, is the same at
// 400, 4033 and 40330 N/m (docs/STIFF_CLOTH.md), so its stretch slider shows nothing there.
#include "run_process.hpp"
#include "user_session.hpp"

#include "clothsim/material.hpp"
#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using Catch::Contains;
using namespace clothsim::test;

namespace {

// The panel's rows in a 1280 x 720 window (the Springs section open, as every scene starts).
constexpr int kStretchY = 266;
constexpr float kStretchWarpX0 = 8.0f, kStretchWeftX0 = 123.0f;  // the two slider frames' left edges
constexpr const char* kDamping = "117 373";
constexpr const char* kDampingReset = "360 373";
constexpr const char* kForcesHeader = "53 465";
constexpr const char* kWindX = "45 511";  // with Forces open
constexpr const char* kSave = "65 151";

// Where stretch `value` (N/m) puts the knob of a slider whose frame starts at x0: the slider is logarithmic
// over [1, 1e5] N/m across 98 px of travel, the knob's centre 7 px in from the frame (ImGui 1.86's
// SliderBehavior: 2 px grab padding, half of the 10 px grab).
int stretch_knob_x(float x0, float value) { return static_cast<int>(std::lround(x0 + 7.0f + 98.0f * std::log10(value) / 5.0f)); }
constexpr int kDecadePx = 20;  // 98 px over 5 decades, rounded: a drag of 20 px multiplies by 10.5

std::string xy(int x, int y) { return std::to_string(x) + " " + std::to_string(y); }
std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", v);
    return text;
}

// The session's own actions: waits on the simulated time in the log, and marks of which frame a change began
// and ended in. `frame` and `settle` wait on the log too (two and three more rows: one and two whole frames
// since the call), which costs nothing, where the F12 screenshots they replace write PNGs.
const char* kLogActions = R"sh(
rows() { awk 'END { print NR }' frames.csv 2>/dev/null; }
rows_more() {
  local n; n=$(rows)
  for _ in $(seq 3000); do [ "$(rows)" -ge $((n + $1)) ] && return; kill -0 $app 2>/dev/null || return; sleep 0.02; done
}
frame() { rows_more 2; }
settle() { rows_more 3; }  # two whole frames after the call
sim_time() { awk -F, 'END { print $6 }' frames.csv 2>/dev/null; }  # (cut is the knife's action)
wait_until() {
  for _ in $(seq 3000); do
    t=$(sim_time); [ -n "$t" ] && awk "BEGIN { exit !($t >= $1) }" && return
    kill -0 $app 2>/dev/null || return; sleep 0.1
  done
  echo "wait_until $1: the simulated time stayed at $(sim_time)" >&2
}
wait_more() { wait_until "$(awk "BEGIN { print $(sim_time) + $1 }")"; }
mark() { echo "$1 $(awk -F, 'END { print $1 }' frames.csv)" >> marks.txt; }
)sh";

struct Row {
    double time, max_move, max_speed, mean_strain, centroid_x, centroid_y, broken_springs;
};

std::vector<Row> read_log(const fs::path& file) {
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    REQUIRE(line.starts_with("frame,frame_ms,simulation_ms,render_ms,substeps,time,max_move,max_speed,mean_strain,"
                             "kinetic_energy,centroid_x,"));
    std::vector<Row> rows;
    while (std::getline(in, line)) {
        std::vector<double> v;
        std::stringstream fields(line);
        for (std::string f; std::getline(fields, f, ',');) v.push_back(std::strtod(f.c_str(), nullptr));
        if (v.size() != 14) break;  // the last row, cut off as the app was writing it
        rows.push_back({v[5], v[6], v[7], v[8], v[10], v[11], v[13]});
    }
    return rows;
}

std::map<std::string, std::size_t> read_marks(const fs::path& file) {
    std::map<std::string, std::size_t> marks;
    std::ifstream in(file);
    std::string name;
    std::size_t frame = 0;
    while (in >> name >> frame) marks[name] = frame;
    return marks;
}

// The rows of a change: from the frame it began in to 2 simulated seconds after the frame it ended in.
struct Window {
    std::size_t begin, end;  // row indices: [begin, end)
    std::size_t changed;     // the row the change's last action ended in
};
Window change_window(const std::vector<Row>& rows, const std::map<std::string, std::size_t>& marks, const std::string& name,
                     double seconds = 2.0) {
    REQUIRE(marks.count(name + "-begin"));
    REQUIRE(marks.count(name + "-end"));
    const std::size_t begin = marks.at(name + "-begin") - 1, last = marks.at(name + "-end") - 1;
    REQUIRE(last < rows.size());
    std::size_t end = last;
    while (end < rows.size() && rows[end].time <= rows[last].time + seconds) ++end;
    INFO(name << ": the log ends " << rows.back().time - rows[last].time << " s after the change");
    REQUIRE(rows.back().time >= rows[last].time + 0.95 * seconds);
    return {begin, end, last};
}

struct Expect {
    bool stretch_shows = true;
    bool wind_shows = true;
    // tear rips free in its gusts (sooner with the wind typed stronger) and may lie slack on the ground by the
    // time the stretch is dragged: then it has no strain for the stretch to change.
    bool may_tear_free = false;
};

void tune_live(const std::string& name, Expect expect) {
    const clothsim::Scene scene = clothsim::load_scene(name);
    REQUIRE(scene.material.enabled);
    REQUIRE(scene.settings.springs.damping > 0.0f);
    const glm::vec2 stretch = scene.material.stretch;
    const float wind_x = scene.settings.forces.wind.x, damping = scene.settings.springs.damping;
    const int warp = stretch_knob_x(kStretchWarpX0, stretch.x), weft = stretch_knob_x(kStretchWeftX0, stretch.y);
    auto drag_stretch = [&](int from, int to) {
        return "drag " + xy(warp + from, kStretchY) + " " + xy(warp + to, kStretchY) + "\n" +  //
               "drag " + xy(weft + from, kStretchY) + " " + xy(weft + to, kStretchY) + "\n";
    };
    auto typed = [](const char* at, const std::string& value) {
        // The text and a quick Return in one go: ImGui takes a frame's characters before its keys.
        return std::string("ctrl_click ") + at + "\nkey ctrl+a\nxdotool type --delay 40 " + value +
               "\nxdotool key Return\nsettle\n";
    };
    const std::string actions =
        std::string(kLogActions) + "wait_until 0.5\n" +
        // The wind, 6 m/s more along +x, and back.
        "click " + kForcesHeader + "\nmark wind-begin\n" + typed(kWindX, number(wind_x + 6.0f)) + "mark wind-end\n" +
        "wait_more 2\n" + typed(kWindX, number(wind_x)) +
        // The damping to 10x and 0.1x, then its reset button.
        "mark damping10-begin\n" + typed(kDamping, number(10.0f * damping)) + "mark damping10-end\nwait_more 0.5\n" +
        "mark damping01-begin\n" + typed(kDamping, number(0.1f * damping)) + "mark damping01-end\nwait_more 0.5\n" +
        "click " + kDampingReset + "\n" +
        // The stretch slider dragged a decade up and then two down.
        "mark stretch10-begin\n" + drag_stretch(0, kDecadePx) + "mark stretch10-end\nwait_more 1\n" +
        "mark stretch01-begin\n" + drag_stretch(kDecadePx, -kDecadePx) + "mark stretch01-end\nwait_more 1\n" +
        "click " + kSave + "\nwait_for " + name + "-edited.toml\nquit\n";

    const TempDir dir("live_tuning_" + name);
    const RunResult r = run_user_session(dir, {"--scene", name, "--frame-times", (dir / "frames.csv").string()}, actions,
                                         zenity_saving_as_proposed(dir));
    CAPTURE_RUN(r);
    REQUIRE(r.code == 0);
    CHECK_THAT(r.err, !Contains("clothsim:") && !Contains("wait_until"));  // no guard, pause or failed rebuild

    // The document has what the hands left: the stretch at about 0.1x, the wind back, the damping reset.
    const fs::path saved = dir / (name + "-edited.toml");
    REQUIRE(fs::exists(saved));
    const clothsim::Scene reopened = clothsim::load_scene(saved.string());
    CHECK(reopened.material.stretch.x / stretch.x == Approx(0.1).epsilon(0.3));
    CHECK(reopened.material.stretch.y / stretch.y == Approx(0.1).epsilon(0.3));
    CHECK(reopened.settings.forces.wind.x == Approx(wind_x).margin(1e-5));
    CHECK(reopened.settings.springs.damping == damping);

    const std::vector<Row> rows = read_log(dir / "frames.csv");
    const std::map<std::string, std::size_t> marks = read_marks(dir / "marks.txt");
    REQUIRE(rows.size() > 10);
    // Continuity: no particle moves further in a frame than the fastest speed seen in the session carries it
    // in the frame's simulated time (plus what gravity adds from rest, and a millimetre of slack). The speeds
    // are sampled at frame ends: a flapping curtain's peak inside a slow frame can pass every speed sampled
    // before it (0.5015 m against 0.4990 at 9 frames a second), so the bound is the session's fastest.
    double fastest = 0.0;
    for (const Row& row : rows) fastest = std::max(fastest, row.max_speed);
    for (std::size_t k = 1; k < rows.size(); ++k) {
        const double dt = rows[k].time - rows[k - 1].time;
        INFO("frame " << k + 1 << " at " << rows[k].time << " s: a particle moved " << rows[k].max_move
                      << " m; the fastest speed seen is " << fastest << " m/s");
        REQUIRE(dt >= 0.0);  // a restart sets the time back to 0
        REQUIRE(rows[k].max_move <= fastest * dt + 0.5 * 9.81 * dt * dt + 1e-3);
    }
    auto extreme = [&](Window w, auto field, bool largest) {
        double e = largest ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
        for (std::size_t k = w.begin; k < w.end; ++k) e = largest ? std::max(e, field(rows[k])) : std::min(e, field(rows[k]));
        return e;
    };
    const auto centroid_x = [](const Row& row) { return row.centroid_x; };
    // A sheet that may tear has torn free when it lies slack as the stretch is dragged, or when its centroid
    // falls below where a sheet still hanging from its top row can reach (the top row's height less the
    // sheet's length at the tear strain): CI caught one falling through the drag up and lying on the ground
    // through the drag down, its strain 1e-4 and then -1e-6 with no spring torn in between.
    if (expect.stretch_shows) {
        const Window up = change_window(rows, marks, "stretch10", 1.0), down = change_window(rows, marks, "stretch01", 1.0);
        bool torn_free = false;
        if (expect.may_tear_free) {
            const double lowest_held = double(scene.cloth.origin.y) -
                                       double(scene.cloth.size.y) * (1.0 + double(scene.settings.springs.tear_strain));
            double lowest = std::numeric_limits<double>::infinity();
            for (std::size_t k = up.begin; k < down.end; ++k) lowest = std::min(lowest, rows[k].centroid_y);
            torn_free = rows[up.begin].mean_strain < 1e-5 || lowest < lowest_held;  // slack: ~0 or compressed
            if (torn_free)
                WARN(name << " had torn free when the stretch was dragged: mean strain " << rows[up.begin].mean_strain
                          << ", the centroid down to " << lowest << " m (a held sheet's stays above " << lowest_held
                          << " m)");
        }
        if (!torn_free) {
            // The strain, averaged over the second after each drag ended, at 0.1x against 10x (100 times softer): a
            // single frame's strain is no measure, as a moving cloth's (fold's, flag's) swings 2x by itself.
            auto average = [&](Window w) {
                double sum = 0.0;
                for (std::size_t k = w.changed; k < w.end; ++k) sum += rows[k].mean_strain;
                return sum / double(w.end - w.changed);
            };
            // At 1x, the half second of simulated time before the drag up (a single frame caught the flag slack at a
            // tenth of its mean).
            double at_one = 0.0;
            std::size_t frames = 0;
            for (std::size_t k = up.begin + 1; k-- > 0 && rows[k].time >= rows[up.begin].time - 0.5;) {
                at_one += rows[k].mean_strain;
                ++frames;
            }
            at_one /= double(frames);
            const double stiff = average(up), soft = average(down);
            INFO("mean strain over the half second before 10x " << at_one << ", over the second at 10x " << stiff
                                                                << ", at 0.1x " << soft);
            // A sheet that may tear can do so at 0.1x (softer, it stretches to the tear strain): its strain then
            // measures what is left hanging, not the stiffness.
            if (expect.may_tear_free && rows[down.end - 1].broken_springs > rows[up.begin].broken_springs) {
                WARN(name << " tore while the stretch was dragged (" << rows[up.begin].broken_springs << " -> "
                          << rows[down.end - 1].broken_springs << " broken springs)");
            } else {
                CHECK(soft >= 3.0 * stiff);
            }
            CHECK(stiff < at_one);
        }
    }
    if (expect.wind_shows) {
        const Window wind = change_window(rows, marks, "wind");
        const double moved = extreme(wind, centroid_x, true) - rows[wind.begin].centroid_x;
        INFO("the centroid moved " << moved << " m along the wind");
        CHECK(moved >= 3e-3);
    }
    for (const char* change : {"damping10", "damping01"}) {  // each ran 0.5 s: continuity is what they check
        const Window w = change_window(rows, marks, change, 0.5);
        CHECK(w.end > w.begin);
    }
}

}  // namespace

TEST_CASE("live tuning: curtain takes wind, damping and stretch while it runs", "[every-scene]") { tune_live("curtain", {}); }
TEST_CASE("live tuning: cusick takes wind, damping and stretch while it runs", "[every-scene]") { tune_live("cusick", {}); }
TEST_CASE("live tuning: drape-cube takes wind, damping and stretch while it runs", "[every-scene]") {
    tune_live("drape-cube", {});
}
TEST_CASE("live tuning: drape-sphere takes wind, damping and stretch while it runs", "[every-scene]") {
    tune_live("drape-sphere", {});
}
TEST_CASE("live tuning: falling, asleep flat on the ground, takes them without moving", "[every-scene]") {
    tune_live("falling", {.stretch_shows = false, .wind_shows = false});
}
TEST_CASE("live tuning: flag takes wind, damping and stretch while it runs", "[every-scene]") { tune_live("flag", {}); }
TEST_CASE("live tuning: fold takes wind, damping and stretch while it runs", "[every-scene]") { tune_live("fold", {}); }
TEST_CASE("live tuning: hanging takes wind, damping and stretch while it runs", "[every-scene]") {
    tune_live("hanging", {});
}
TEST_CASE("live tuning: mannequin-drape takes wind, damping and stretch while it runs", "[every-scene]") {
    tune_live("mannequin-drape", {});
}
TEST_CASE("live tuning: chair-drape takes wind, damping and stretch while it runs", "[every-scene]") {
    tune_live("chair-drape", {});
}
TEST_CASE("live tuning: moving-ball takes wind and damping while the ball rolls (the ball pushes its cloth together: "
          "in compression, its mean strain shows no stretch)",
          "[every-scene]") {
    tune_live("moving-ball", {.stretch_shows = false});
}
TEST_CASE("live tuning: pile takes damping and stretch while it runs (wind along a flat cloth exerts no force)",
          "[every-scene]") {
    tune_live("pile", {.wind_shows = false});
}
TEST_CASE("live tuning: skirt, a mesh cloth, takes wind, damping and stretch while it runs", "[every-scene]") {
    tune_live("skirt", {});
}
TEST_CASE("live tuning: stiff-drape takes wind and damping (its XPBD strain is iteration-bound)", "[every-scene]") {
    tune_live("stiff-drape", {.stretch_shows = false});
}
TEST_CASE("live tuning: stiff-hanging takes wind, damping and stretch while it runs", "[every-scene]") {
    tune_live("stiff-hanging", {});
}
TEST_CASE("live tuning: tablecloth takes wind, damping and stretch while it runs", "[every-scene]") {
    tune_live("tablecloth", {});
}
TEST_CASE("live tuning: tear takes wind, damping and stretch while it runs (unless it has torn free)", "[every-scene]") {
    tune_live("tear", {.may_tear_free = true});
}

TEST_CASE("live tuning: unticking curved lets a knit hang longer and ticking it back holds it, without a restart",
          "[stretch_curve]") {
    // hanging in gray-interlock at its measured 33 / 69 N/m (16 x 16, no tethers): linear it hangs at a mean strain
    // of 1.6% after 4 s, with its measured curve at 1.0% (docs/MATERIAL.md, "Nonlinear stretch"). The "curved"
    // checkbox sits on the fabric row; the log's mean strain says what each click did.
    constexpr const char* kCurved = "299 220";
    const std::string actions = std::string(kLogActions) + "wait_until 3\n" +  //
                                "mark off-begin\nclick " + kCurved + "\nsettle\nmark off-end\nwait_more 2\n" +
                                "mark on-begin\nclick " + kCurved + "\nsettle\nmark on-end\nwait_more 2\n" +
                                "click " + kSave + "\nwait_for hanging-edited.toml\nquit\n";
    const TempDir dir("live_tuning_curve");
    const RunResult r = run_user_session(dir,
                                         {"--scene", "hanging", "--set", "material.preset=gray-interlock", "--set",
                                          "material.stretch=[33.2, 69.0]", "--set", "cloth.rows=16", "--set",
                                          "cloth.cols=16", "--set", "springs.tether_strain=0", "--frame-times",
                                          (dir / "frames.csv").string()},
                                         actions, zenity_saving_as_proposed(dir));
    CAPTURE_RUN(r);
    REQUIRE(r.code == 0);
    CHECK_THAT(r.err, !Contains("clothsim:") && !Contains("wait_until"));
    const std::vector<Row> rows = read_log(dir / "frames.csv");
    const std::map<std::string, std::size_t> marks = read_marks(dir / "marks.txt");
    for (std::size_t k = 1; k < rows.size(); ++k) REQUIRE(rows[k].time >= rows[k - 1].time);  // no restart
    // The mean strain over the last second of each window, and over the half second before the first click.
    auto last_second = [&](Window w) {
        double sum = 0.0;
        std::size_t n = 0;
        for (std::size_t k = w.changed; k < w.end; ++k) {
            if (rows[k].time >= rows[w.end - 1].time - 1.0) sum += rows[k].mean_strain, ++n;
        }
        return sum / double(n);
    };
    const Window off = change_window(rows, marks, "off"), on = change_window(rows, marks, "on");
    double curved = 0.0;
    std::size_t n = 0;
    for (std::size_t k = off.begin + 1; k-- > 0 && rows[k].time >= rows[off.begin].time - 0.5;) curved += rows[k].mean_strain, ++n;
    curved /= double(n);
    const double linear = last_second(off), again = last_second(on);
    INFO("mean strain curved " << curved << ", linear " << linear << ", curved again " << again);
    CHECK(linear > 1.3 * curved);
    CHECK(again < 0.8 * linear);
    // The document holds the measured curve again, the stretch as set.
    const clothsim::Scene saved = clothsim::load_scene((dir / "hanging-edited.toml").string());
    const clothsim::MaterialPreset* knit = clothsim::find_material_preset("gray-interlock");
    REQUIRE(knit);
    CHECK(saved.material.stretch_curve == clothsim::preset_stretch_curve(*knit));
    CHECK(saved.material.stretch.x == Approx(33.2f));
}
