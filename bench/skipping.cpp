// Each figure compares two simulations that must give the same positions (or one asleep), timed in
// alternation: repetition r runs A then B (B then A on odd r) for the same number of frames, so the machine's
// drift hits both alike. The ratio reported is the median of the per-repetition ratios B / A.
#include "skipping.hpp"

#include "clothsim/normals.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include "per_spring_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace clothsim::bench {
namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Pair {
    std::string name;
    int size = 0;
    std::string a, b;      // what A and B are
    double a_ms = 0.0, b_ms = 0.0;  // median ms per frame
    double ratio = 0.0;    // median of B / A per repetition
    std::string note;
    int threads = 0;       // the fast solver's threads, where the case sets them
};

// Times `frame_a` and `frame_b` alternately; each repetition calls `setup` (untimed) before `calls` frames of
// each, so both can start from the same state.
Pair time_pair(const std::function<void()>& frame_a, const std::function<void()>& frame_b, const SkippingOptions& o,
               const std::function<void(bool b)>& setup = nullptr) {
    long long calls = 1;
    for (;;) {  // calibrate on A
        if (setup) setup(false);
        const auto t0 = Clock::now();
        for (long long i = 0; i < calls; ++i) frame_a();
        const double t = std::chrono::duration<double>(Clock::now() - t0).count();
        if (t >= o.min_seconds) break;
        calls = std::max(calls * 2, static_cast<long long>(calls * o.min_seconds / std::max(t, 1e-9)));
    }
    auto run = [&](const std::function<void()>& f, bool b) {
        if (setup) setup(b);
        const auto t0 = Clock::now();
        for (long long i = 0; i < calls; ++i) f();
        return std::chrono::duration<double, std::milli>(Clock::now() - t0).count() / double(calls);
    };
    std::vector<double> a, b, ratio;
    for (int r = 0; r < o.repeats; ++r) {
        double ta, tb;
        if (r % 2 == 0) {
            ta = run(frame_a, false);
            tb = run(frame_b, true);
        } else {
            tb = run(frame_b, true);
            ta = run(frame_a, false);
        }
        a.push_back(ta);
        b.push_back(tb);
        ratio.push_back(tb / ta);
    }
    Pair p;
    p.a_ms = median(a);
    p.b_ms = median(b);
    p.ratio = median(ratio);
    return p;
}

// A bundled scene with its cloth resized, and the substeps a finer grid needs to stay stable (0.67 of the
// critical substep, as the bundled scenes are set).
// In its per-spring form (tests/fixtures/per_spring_scenes.hpp): the workload docs/PERFORMANCE.md's figures measured,
// and the zero-stiffness cases switch skip-one bending springs off.
Scene resized(const std::string& name, int size) {
    Scene s = per_spring_scene(name);
    s.cloth.rows = s.cloth.cols = size;
    s.settings.solver.sleep_speed = 0.0f;  // awake throughout unless a case says otherwise
    const MassSpring sim = build_simulation(s);
    s.settings.integration.substeps = std::max(s.settings.integration.substeps,
                                               auto_substeps(stability_limit(sim), s.settings.integration.dt, 0.67f));
    return s;
}
Scene hanging(int size) { return resized("hanging", size); }

// The same cloth without its bending springs: a topology the fast solver sweeps with that direction absent.
MassSpring without_bending(const MassSpring& sim) {
    Topology t = sim.topology();
    std::erase_if(t.springs, [](const Spring& s) { return s.kind == SpringKind::Bending; });
    return MassSpring(t, sim.state(), sim.settings());
}

// What the app does with the core every frame: one guarded step, then normals when the cloth moved.
struct AppFrame {
    explicit AppFrame(MassSpring s) : sim(std::move(s)) {}
    MassSpring sim;
    std::vector<glm::vec3> normals;
    std::uint64_t drawn = 0;
    void operator()() {
        std::string log;
        run_guarded(sim, 1, GuardSettings{}, log);
        if (sim.change_stamp() != drawn) {
            compute_vertex_normals(sim.topology(), sim.state().position, normals);
            drawn = sim.change_stamp();
        }
    }
};

// One timed window of `frames` frames from the state `from` (restored each time, so a phase stays what it
// says), with a fresh profile.
constexpr int kWindowFrames = 10;
void run_window(MassSpring& sim, const MassSpring& from) {
    sim = from;
    sim.reset_profile();
    sim.run_steps(kWindowFrames);
}

}  // namespace

int run_skipping(const SkippingOptions& o) {
    std::vector<Pair> pairs;
    try {
        for (int size : o.sizes) {
            // 1. A sphere far from the cloth against no sphere: one simulation object restored from the same
            //    snapshot before each repetition (same memory, same trajectory), the sphere switched on for B.
            {
                const MassSpring start = build_simulation(hanging(size));
                MassSpring sim = start;
                StepProfile far_profile;
                auto setup = [&](bool far) {
                    if (far) far_profile.add(sim.profile());  // the previous B window's profile
                    sim = start;
                    {
                        SimulationSettings moved = sim.settings();
                        std::erase_if(moved.colliders.shapes, [](const Collider& c) { return c.kind() == 0; });
                        if (far) {
                            moved.colliders.shapes.insert(moved.colliders.shapes.begin(),
                                                          Collider{SphereCollider{{6.0f, 1.0f, 6.0f}, 0.3f}, 0.3f, true, {}});
                        }
                        sim.apply(moved);
                    }
                    sim.reset_profile();
                };
                Pair p = time_pair([&] { sim.run_steps(1); }, [&] { sim.run_steps(1); }, o, setup);
                p.name = "far-sphere";
                p.a = "no sphere";
                p.b = "sphere 8 m away";
                char note[160];
                std::snprintf(note, sizeof note, "colliders stage %.3f%% of the stages' time (profile); the sphere's %lld of %lld blocks tested",
                              100.0 * far_profile.ms_of(Stage::Colliders) / far_profile.total_ms(),
                              far_profile.blocks_tested[0], far_profile.blocks_offered[0]);
                p.note = note;
                p.size = size;
                pairs.push_back(p);
            }
            // 2. Bending stiffness 0 against no bending springs at all.
            {
                Scene zero = hanging(size);
                zero.settings.springs.bending = glm::vec2(0.0f);
                MassSpring b = build_simulation(zero);
                MassSpring a = without_bending(b);
                Pair p = time_pair([&] { a.run_steps(1); }, [&] { b.run_steps(1); }, o);
                p.name = "bending-zero";
                p.a = "no bending springs";
                p.b = "bending stiffness 0";
                p.size = size;
                p.note = a.plan().path == StepPath::FastVerlet && b.plan().path == StepPath::FastVerlet ? "both on the fast solver" : "not both on the fast solver";
                pairs.push_back(p);
            }
            // 3. A sleeping cloth against an awake one, per app frame (guarded step and normals).
            {
                Scene awake_scene = hanging(size);
                Scene settle = hanging(size);
                settle.settings.springs.damping = 4.0f;
                settle.settings.solver.sleep_speed = 0.002f;
                AppFrame awake{build_simulation(awake_scene)};
                AppFrame asleep{build_simulation(settle)};
                for (int i = 0; i < 60 * 120 && !asleep.sim.asleep(); ++i) asleep.sim.run_steps(1);
                if (!asleep.sim.asleep()) throw std::runtime_error("the settling cloth did not fall asleep in 120 s");
                const double slept_at = asleep.sim.time();
                Pair p = time_pair(std::ref(awake), std::ref(asleep), o);
                p.name = "sleeping";
                p.a = "awake";
                p.b = "asleep";
                p.size = size;
                char note[96];
                std::snprintf(note, sizeof note, "fell asleep at t = %.1f s", slept_at);
                p.note = note;
                pairs.push_back(p);
            }
            // 4. Profiling's own cost: the clock reads around each stage (one object, as in 1).
            {
                const MassSpring start = build_simulation(hanging(size));
                MassSpring sim = start;
                auto setup = [&](bool on) {
                    sim = start;
                    sim.set_profiling(on);
                };
                Pair p = time_pair([&] { sim.run_steps(1); }, [&] { sim.run_steps(1); }, o, setup);
                p.name = "profiling";
                p.a = "profiling off";
                p.b = "profiling on";
                p.size = size;
                pairs.push_back(p);
            }
        }
        // 5. Drape on the sphere: the sphere stage with the broad phase against testing every particle, while
        //    the cloth falls (little contact) and once it has draped.
        for (int size : {40, 128}) {
            Scene on = resized("drape-sphere", size);
            Scene off = on;
            off.settings.solver.broad_phase = false;
            for (const auto& [phase, start] : {std::pair{"falling", 0.0}, std::pair{"draped", 2.5}}) {
                MassSpring a = build_simulation(off), b = build_simulation(on);
                a.run_steps(std::llround(start / on.settings.integration.dt));
                b.run_steps(std::llround(start / on.settings.integration.dt));
                if (!a.all_finite() || !b.all_finite()) throw std::runtime_error("the drape became non-finite");
                const MassSpring a0 = a, b0 = b;
                const int frames = kWindowFrames;
                auto window = run_window;
                std::vector<double> sphere_a, sphere_b;
                Pair p = time_pair(
                    [&] {
                        window(a, a0);
                        sphere_a.push_back(a.profile().ms_of(Stage::Colliders) / frames);
                    },
                    [&] {
                        window(b, b0);
                        sphere_b.push_back(b.profile().ms_of(Stage::Colliders) / frames);
                    },
                    o);
                p.name = std::string("drape-") + phase;
                p.size = size;
                p.a = "every particle";
                p.b = "broad phase";
                const double sa = median(sphere_a), sb = median(sphere_b);
                char note[160];
                std::snprintf(note, sizeof note, "colliders stage %.4f -> %.4f ms/frame (%.2fx); %lld of %lld blocks tested",
                              sa, sb, sa / sb, b.profile().blocks_tested[0], b.profile().blocks_offered[0]);
                p.note = note;
                p.a_ms /= frames;
                p.b_ms /= frames;
                pairs.push_back(p);
            }
        }
        // 6. Self-collision (issue 17's targets) at 64 x 64, the scene's own form and auto substeps at 0.7:
        //    a flat cloth falling (falling, untilted, before it lands) and drape-cube once draped (2.5 s in,
        //    its corners folded). Both windows restart from the same state, A without collision.self.
        for (const auto& [scene_name, start, label] : {std::tuple{"falling", 0.0, "self-falling"},
                                                       std::tuple{"drape-cube", 2.5, "self-drape-cube"}}) {
            Scene on = load_scene(scene_name);
            on.cloth.rows = on.cloth.cols = 64;
            if (std::string(scene_name) == "falling") on.cloth.v_axis = glm::vec3(0.0f, 0.0f, 1.0f);  // flat
            on.settings.solver.sleep_speed = 0.0f;
            on.settings.collision.self = true;
            if (o.self_threads > 0) on.settings.solver.threads = o.self_threads;
            {
                const MassSpring probe = build_simulation(on);
                on.settings.integration.substeps = auto_substeps(stability_limit(probe), on.settings.integration.dt, 0.7f);
            }
            Scene off = on;
            off.settings.collision.self = false;
            MassSpring b = build_simulation(on);
            // At least one step: the stage is built at its first substep, once per simulation, and the windows
            // restart from this state, so none of them pays for building it.
            b.run_steps(std::max(1LL, std::llround(start / on.settings.integration.dt)));
            if (!b.all_finite()) throw std::runtime_error(std::string(scene_name) + " became non-finite");
            MassSpring a = b;  // the same state, self-collision off
            a.apply(off.settings);
            const MassSpring a0 = a, b0 = b;
            const int frames = kWindowFrames;
            auto window = run_window;
            std::vector<double> self_ms;
            Pair p = time_pair([&] { window(a, a0); },
                               [&] {
                                   window(b, b0);
                                   self_ms.push_back(b.profile().ms_of(Stage::SelfCollision) / frames);
                               },
                               o);
            p.name = label;
            p.size = 64;
            p.threads = b.solver_threads();
            p.a = "collision.self off";
            p.b = "collision.self on";
            char note[200];
            std::snprintf(note, sizeof note, "self collision stage %.3f ms/frame; %lld of %lld substeps tested, %lld tiles in the narrow phase",
                          median(self_ms), b.profile().self_tests, b.profile().substeps,
                          b.profile().self_tiles_active);
            p.note = note;
            p.a_ms /= frames;
            p.b_ms /= frames;
            pairs.push_back(p);
        }
    } catch (const std::exception& e) {
        std::cerr << "clothsim-bench skipping: error: " << e.what() << "\n";
        return 2;
    }
    std::printf("%-16s %5s %-20s %-20s %10s %10s %8s  %s\n", "case", "size", "A", "B", "A ms/frame", "B ms/frame",
                "B / A", "note");
    for (const Pair& p : pairs) {
        const std::string threads = p.threads > 0 ? "; " + std::to_string(p.threads) + " thread(s)" : "";
        std::printf("%-16s %5d %-20s %-20s %10.4f %10.4f %8.4f  %s%s\n", p.name.c_str(), p.size, p.a.c_str(), p.b.c_str(),
                    p.a_ms, p.b_ms, p.ratio, p.note.c_str(), threads.c_str());
    }
    if (!o.csv.empty()) {
        std::ofstream out(o.csv);
        out << "case,size,a,b,a_ms_per_frame,b_ms_per_frame,median_ratio_b_over_a,note\n";
        for (const Pair& p : pairs) {
            out << p.name << ',' << p.size << ',' << p.a << ',' << p.b << ',' << p.a_ms << ',' << p.b_ms << ','
                << p.ratio << ",\"" << p.note << "\"\n";
        }
        if (!out) {
            std::cerr << "clothsim-bench skipping: error: cannot write " << o.csv << "\n";
            return 2;
        }
    }
    return 0;
}

}  // namespace clothsim::bench
