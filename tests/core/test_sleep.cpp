// Sleeping (mass_spring.hpp): a cloth slower than solver.sleep_speed for solver.sleep_time, with nothing
// driving it, stops being integrated; any change of the settings, a pin set or moved wakes it from rest.
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "clothsim/scene.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace clothsim;

namespace {

// Every particle's x, y and z equal (==) in both; the first particle that differs is reported.
void require_same_positions(const MassSpring& a, const MassSpring& b) {
    REQUIRE(a.particle_count() == b.particle_count());
    for (std::size_t i = 0; i < a.particle_count(); ++i) {
        const glm::vec3 p = a.position(i), q = b.position(i);
        if (p.x == q.x && p.y == q.y && p.z == q.z) continue;
        FAIL_CHECK("particle " << i << " differs: (" << p.x << ", " << p.y << ", " << p.z << ") vs (" << q.x << ", "
                               << q.y << ", " << q.z << ")");
        REQUIRE(false);
    }
}

void require_positions(const MassSpring& sim, const std::vector<glm::vec3>& expected) {
    REQUIRE(sim.particle_count() == expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        const glm::vec3 p = sim.position(i);
        if (p.x == expected[i].x && p.y == expected[i].y && p.z == expected[i].z) continue;
        FAIL_CHECK("particle " << i << " moved from (" << expected[i].x << ", " << expected[i].y << ", "
                               << expected[i].z << ") to (" << p.x << ", " << p.y << ", " << p.z << ")");
        REQUIRE(false);
    }
}

// Largest distance any particle lies from where it was.
float largest_move(const MassSpring& sim, const std::vector<glm::vec3>& before) {
    float worst = 0.0f;
    for (std::size_t i = 0; i < before.size(); ++i) worst = std::max(worst, glm::length(sim.position(i) - before[i]));
    return worst;
}

// Largest free-particle speed over the last substep, |motion| / substep (m/s): check_sleep bounds it too.
float fastest_free_speed(const MassSpring& sim) {
    const State& st = sim.state();
    float fastest = 0.0f;
    for (std::size_t i = 0; i < st.size(); ++i) {
        if (st.pinned[i]) continue;
        fastest = std::max(fastest, static_cast<float>(glm::length(st.motion.get(i)) / st.substep));
    }
    return fastest;
}

// The hanging cloth, 8 x 8, heavily damped so that it settles in a few simulated seconds (per spring, at the
// 34 substeps a step these tests were written for: sleeping does not depend on the form).
Scene settling_scene() {
    Scene s = per_spring_scene("hanging");
    s.cloth.rows = 8;
    s.cloth.cols = 8;
    s.settings.springs.damping = 4.0f;
    s.settings.solver.sleep_speed = 0.002f;
    s.settings.solver.sleep_time = 0.5f;
    return s;
}

constexpr int kMaxSettleSteps = 60 * 20;

// Steps whole steps until the cloth is asleep; returns how many it took (REQUIREs that it happens).
int settle(MassSpring& sim) {
    for (int step = 1; step <= kMaxSettleSteps; ++step) {
        sim.run_steps(1);
        if (sim.asleep()) return step;
    }
    FAIL("the cloth did not fall asleep in " << kMaxSettleSteps << " steps");
    return 0;
}

MassSpring asleep_cloth() {
    MassSpring sim = build_simulation(settling_scene());
    settle(sim);
    REQUIRE(sim.asleep());
    REQUIRE(sim.asleep());
    return sim;
}

}  // namespace

TEST_CASE("sleep a settling cloth falls asleep and then stays exactly where it is while time goes on", "[sleep]") {
    for (SolverMethod method : {SolverMethod::Fast, SolverMethod::Textbook}) {
        INFO((method == SolverMethod::Fast ? "fast solver" : "textbook solver"));
        Scene scene = settling_scene();
        scene.settings.solver.method = method;
        MassSpring sim = build_simulation(scene);
        CHECK_FALSE(sim.asleep());
        CHECK(sim.plan().may_sleep);
        const int steps = settle(sim);
        INFO("asleep after " << steps << " steps");
        CHECK(steps > 30);  // not before sleep_time has passed at all
        CHECK(sim.asleep());
        CHECK(sim.energy().kinetic == 0.0);
        for (const glm::vec3& v : sim.velocities()) CHECK(v == glm::vec3(0.0f));

        const std::vector<glm::vec3> held = sim.positions();
        const double t0 = sim.time();
        const std::uint64_t stamp = sim.change_stamp();
        const long long slept = sim.profile().slept_substeps;
        const long long stepped = sim.profile().substeps;
        sim.run_steps(20);
        require_positions(sim, held);
        CHECK(sim.asleep());
        CHECK(sim.time() == Approx(t0 + 20.0 * scene.settings.integration.dt).epsilon(1e-6));
        CHECK(sim.energy().kinetic == 0.0);
        CHECK(sim.change_stamp() == stamp);
        CHECK(sim.profile().slept_substeps == slept + 20 * scene.settings.integration.substeps);
        CHECK(sim.profile().substeps == stepped);  // no substep was integrated
    }
}

TEST_CASE("sleep only freezes a cloth that was slower than sleep_speed for the whole sleep_time", "[sleep]") {
    // mass_spring.hpp: at the end of every step a free particle's speed is its displacement since the last
    // check over the time between; the cloth sleeps once every speed has stayed under sleep_speed for
    // sleep_time (and no substep motion exceeded 100 x sleep_speed x substep).
    const Scene scene = settling_scene();
    const float sleep_speed = scene.settings.solver.sleep_speed;
    MassSpring sim = build_simulation(scene);
    std::vector<float> speeds, substep_speeds;  // per step: the fastest free particle over it, over its last substep
    std::vector<double> calm;                   // per step: calm_seconds() after it
    double calm_expected = 0.0;
    for (int step = 0; step < kMaxSettleSteps && !sim.asleep(); ++step) {
        // A copy that may not sleep shows the motion the step leaves before sleeping zeroes it (sleep_speed
        // changes nothing else: it does not enter the physics).
        MassSpring probe = sim;
        test::edit_settings(probe, [&](SimulationSettings& edit) { edit.solver.sleep_speed = 0.0f; });
        probe.run_steps(1);
        const std::vector<glm::vec3> before = sim.positions();
        const double t0 = sim.time();
        sim.run_steps(1);
        require_same_positions(sim, probe);
        CHECK_FALSE(probe.asleep());
        float fastest = 0.0f;
        for (std::size_t i = 0; i < before.size(); ++i) {
            if (sim.particle(i).pinned) continue;
            fastest = std::max(fastest, glm::length(sim.position(i) - before[i]) / static_cast<float>(sim.time() - t0));
        }
        speeds.push_back(fastest);
        substep_speeds.push_back(fastest_free_speed(probe));
        calm.push_back(sim.calm_seconds());
        // The first check only takes the positions as its baseline.
        const bool is_calm = step > 0 && fastest < sleep_speed && substep_speeds.back() < 100.0f * sleep_speed;
        calm_expected = is_calm ? calm_expected + (sim.time() - t0) : 0.0;
        if (!sim.asleep()) {
            INFO("step " << step + 1 << ": fastest " << fastest << " m/s, calm " << sim.calm_seconds() << " s");
            // Round-off at the threshold itself could tip either way: only check clear cases.
            if (std::abs(fastest - sleep_speed) > 1e-3f * sleep_speed) {
                CHECK(sim.calm_seconds() == Approx(calm_expected).margin(1e-9));
            }
        }
    }
    REQUIRE(sim.asleep());
    const auto window = static_cast<std::size_t>(
        std::lround(scene.settings.solver.sleep_time / scene.settings.integration.dt));  // 30 steps
    REQUIRE(speeds.size() > window);
    for (std::size_t k = speeds.size() - window; k < speeds.size(); ++k) {
        INFO("step " << k + 1 << " of " << speeds.size() << ": fastest free particle " << speeds[k]
                     << " m/s over the step, " << substep_speeds[k] << " m/s over its last substep");
        CHECK(speeds[k] < sleep_speed);
        CHECK(substep_speeds[k] < 100.0f * sleep_speed);
    }
    // It fell asleep as soon as it could: one step earlier the calm had not lasted sleep_time yet.
    const std::size_t before = speeds.size() - window - 1;
    INFO("step " << before + 1 << ": fastest free particle " << speeds[before] << " m/s, calm " << calm[before]
                 << " s");
    CHECK(calm[before] == 0.0);
}

TEST_CASE("sleep never freezes a cloth moving faster than sleep_speed", "[sleep]") {
    // Falling freely (no ground, no pins): it only gets faster.
    Scene falling = settling_scene();
    falling.pins.preset = PinPreset::None;
    test::collider(falling.settings.colliders, "ground").enabled = false;
    falling.settings.springs.damping = 0.2f;
    MassSpring sim = build_simulation(falling);
    REQUIRE(sim.plan().may_sleep);
    for (int step = 0; step < 120; ++step) {
        sim.run_steps(1);
        REQUIRE_FALSE(sim.asleep());
    }
    CHECK(sim.profile().slept_substeps == 0);

    // A cloth still swinging: with a threshold far below its speed it stays awake over a short run.
    Scene swinging = settling_scene();
    swinging.settings.solver.sleep_speed = 1e-7f;
    MassSpring swing = build_simulation(swinging);
    for (int step = 0; step < 90; ++step) {
        swing.run_steps(1);
        REQUIRE_FALSE(swing.asleep());
    }

    // An undamped weight bouncing on a spring is slow only for moments, at its turning points: those calm
    // steps are not consecutive and must not add up to sleep_time.
    Scene bounce = test::chain(2, 0.1f, 0.05f, 30.0f);  // period 0.26 s, top speed 0.4 m/s
    bounce.pins.particles = {{0, 0}};
    bounce.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    bounce.settings.integration.substeps = 20;
    bounce.settings.solver.sleep_speed = 0.1f;
    bounce.settings.solver.sleep_time = 0.5f;
    MassSpring bouncing = build_simulation(bounce);
    int calm_steps = 0;
    for (int step = 0; step < 1200; ++step) {  // 20 s
        const glm::vec3 before = bouncing.position(1);
        bouncing.run_steps(1);
        REQUIRE_FALSE(bouncing.asleep());
        const float speed = glm::length(bouncing.position(1) - before) / bounce.settings.integration.dt;
        calm_steps += speed < bounce.settings.solver.sleep_speed;
    }
    CHECK(calm_steps >= 60);  // far more than the 30 steps of sleep_time, but never 30 in a row
}

TEST_CASE("sleep with sleep_time 0 a cloth moving faster than sleep_speed still never sleeps", "[sleep]") {
    // sleep_time 0 (allowed: its range is [0, 1e4]) means "asleep at the first calm check", not "asleep at
    // the first check whatever the speed".
    Scene falling = settling_scene();
    falling.pins.preset = PinPreset::None;
    test::collider(falling.settings.colliders, "ground").enabled = false;
    falling.settings.solver.sleep_time = 0.0f;
    MassSpring sim = build_simulation(falling);
    falling.settings.solver.sleep_speed = 0.0f;
    MassSpring awake = build_simulation(falling);
    const glm::vec3 start = sim.position(0);
    sim.run_steps(10);
    awake.run_steps(10);
    INFO("fell " << start.y - sim.position(0).y << " m in 10 steps; never sleeping it falls "
                 << start.y - awake.position(0).y << " m");
    CHECK_FALSE(sim.asleep());
}

TEST_CASE("sleep a cloth with NaN motion never sleeps, wherever the NaN particle is", "[sleep]") {
    // Two unconnected free particles, no forces: one at rest, one whose velocity (so motion) is NaN.
    // mass_spring.cpp, check_sleep: "NaN never counts as calm".
    for (std::size_t nan_index : {0u, 1u}) {
        INFO("NaN particle " << nan_index);
        Topology t;
        t.rows = 1;
        t.cols = 2;
        SimulationSettings settings;
        settings.forces.gravity = glm::vec3(0.0f);
        test::collider(settings.colliders, "ground").enabled = false;
        settings.solver.sleep_speed = 0.002f;
        settings.solver.sleep_time = 0.5f;
        MassSpring sim(t, test::free_particles({{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}}, 1.0f), settings);
        sim.set_particle(nan_index, sim.position(nan_index), glm::vec3(NAN));
        REQUIRE(std::isnan(sim.state().motion.x[nan_index]));
        sim.run_steps(60);
        CHECK_FALSE(sim.asleep());
    }
}

TEST_CASE("sleep with sleep_speed 0 a cloth at rest never sleeps", "[sleep]") {
    Scene rest = settling_scene();
    rest.settings.forces.gravity = glm::vec3(0.0f);  // springs at rest length, no gravity: nothing moves
    rest.settings.solver.sleep_speed = 0.0f;
    MassSpring never = build_simulation(rest);
    CHECK_FALSE(never.plan().may_sleep);
    never.run_steps(120);
    CHECK_FALSE(never.asleep());
    CHECK(never.profile().slept_substeps == 0);
    CHECK(never.profile().runs_of(Stage::Sleep) == 0);
    // The same cloth with sleeping on falls asleep after sleep_time: the cloth really is at rest.
    rest.settings.solver.sleep_speed = 0.002f;
    MassSpring sleeps = build_simulation(rest);
    sleeps.run_steps(40);
    CHECK(sleeps.asleep());
}

TEST_CASE("sleep wind wakes a sleeping cloth and keeps it awake while it blows", "[sleep]") {
    MassSpring sim = asleep_cloth();
    const std::vector<glm::vec3> held = sim.positions();
    // Across the hanging cloth (it hangs in the x-y plane); the change wakes it at once.
    test::edit_settings(sim, [](SimulationSettings& edit) { edit.forces.wind = {0.0f, 0.0f, 3.0f}; });
    CHECK_FALSE(sim.asleep());
    sim.run_steps(1);
    CHECK_FALSE(sim.asleep());
    CHECK_FALSE(sim.plan().may_sleep);
    CHECK(largest_move(sim, held) > 0.0f);
    for (int step = 0; step < 300; ++step) {  // 5 s: long enough to sleep ten times over in still air
        sim.run_steps(1);
        REQUIRE_FALSE(sim.asleep());
    }
    CHECK(largest_move(sim, held) > 0.01f);  // blown aside
}

TEST_CASE("sleep grabbing a pin wakes a sleeping cloth and it follows", "[sleep]") {
    MassSpring sim = asleep_cloth();
    REQUIRE(sim.particle(0).pinned);  // the hanging cloth's top corner
    const std::vector<glm::vec3> held = sim.positions();
    const std::uint64_t stamp = sim.change_stamp();
    const glm::vec3 to = held[0] + glm::vec3(0.0f, 0.0f, 0.1f);
    sim.move_pinned(0, to);
    CHECK_FALSE(sim.asleep());
    CHECK(sim.change_stamp() != stamp);
    sim.run_steps(5);
    CHECK_FALSE(sim.asleep());
    CHECK(sim.position(0) == to);
    CHECK(sim.position(1).z > held[1].z + 1e-3f);  // its neighbour is pulled along

    MassSpring again = asleep_cloth();
    again.set_pinned(20, true);
    CHECK_FALSE(again.asleep());
    again.set_pinned(20, false);  // unpinned again: it is free to settle, but is not asleep yet
    CHECK_FALSE(again.asleep());
    // move_pinned on a free particle does nothing, so it does not wake a cloth either.
    MassSpring still = asleep_cloth();
    REQUIRE_FALSE(still.particle(20).pinned);
    still.move_pinned(20, glm::vec3(5.0f));
    CHECK(still.asleep());
}

TEST_CASE("sleep moving a collider wakes a sleeping cloth", "[sleep]") {
    SECTION("the ground raised into the cloth pushes it up") {
        MassSpring sim = asleep_cloth();
        const std::vector<glm::vec3> held = sim.positions();
        float lowest = INFINITY;
        for (const glm::vec3& p : held) lowest = std::min(lowest, p.y);
        test::edit_settings(sim, [&](SimulationSettings& edit) { test::plane(edit.colliders).height = lowest + 0.05f; });
        sim.run_steps(1);
        CHECK_FALSE(sim.asleep());
        CHECK(largest_move(sim, held) > 0.04f);
    }
    SECTION("a sphere moved into the cloth") {
        Scene scene = settling_scene();
        test::collider(scene.settings.colliders, "sphere") = Collider{SphereCollider{{0.0f, 0.5f, 3.0f}, 0.2f}, 0.3f, true, {}};  // out of the way
        MassSpring sim = build_simulation(scene);
        settle(sim);
        const std::vector<glm::vec3> held = sim.positions();
        const glm::vec3 middle = held[sim.topology().index(4, 4)];
        test::edit_settings(sim, [&](SimulationSettings& edit) { test::sphere(edit.colliders).center = middle + glm::vec3(0.0f, 0.0f, 0.15f); });
        sim.run_steps(1);
        CHECK_FALSE(sim.asleep());
        CHECK(largest_move(sim, held) > 0.01f);
    }
    SECTION("a collider moved out of reach still wakes it") {
        MassSpring sim = asleep_cloth();
        // A disabled sphere: nothing touches the cloth.
        test::edit_settings(sim, [](SimulationSettings& edit) { test::sphere(edit.colliders).center.x += 1.0f; });
        sim.run_steps(1);
        CHECK_FALSE(sim.asleep());
    }
}

TEST_CASE("sleep any settings change wakes a sleeping cloth and no change keeps it asleep", "[sleep]") {
    MassSpring sim = asleep_cloth();
    sim.apply(sim.settings());  // the same values: no change
    CHECK(sim.asleep());
    sim.run_steps(3);
    CHECK(sim.asleep());

    test::edit_settings(sim, [&](SimulationSettings& edit) { edit.springs.bending *= 2.0f; });
    CHECK_FALSE(sim.asleep());
    CHECK_FALSE(sim.asleep());  // woken at the point of change
    sim.substep();
    CHECK_FALSE(sim.asleep());

    MassSpring heavier = asleep_cloth();
    const std::vector<glm::vec3> held = heavier.positions();
    test::edit_settings(heavier, [&](SimulationSettings& edit) { edit.forces.gravity.y *= 2.0f; });
    heavier.run_steps(10);
    CHECK_FALSE(heavier.asleep());
    CHECK(largest_move(heavier, held) > 1e-3f);  // it sags under the stronger gravity

    MassSpring damped = asleep_cloth();
    test::edit_settings(damped, [&](SimulationSettings& edit) { edit.springs.damping = 5.0f; });
    damped.substep();
    CHECK_FALSE(damped.asleep());
}

TEST_CASE("sleep a woken cloth restarts from rest exactly as a fresh cloth at those positions", "[sleep]") {
    MassSpring sim = asleep_cloth();
    test::edit_settings(sim, [](SimulationSettings& edit) { edit.forces.gravity.y = -5.0f; });  // the change that wakes it
    // A fresh simulation of the same cloth, at the same positions, started at rest with the new settings.
    MassSpring fresh(sim.topology(), sim.state(), sim.settings());
    sim.substep();  // wakes, restarts from rest and integrates one substep
    fresh.substep();
    REQUIRE_FALSE(sim.asleep());
    require_same_positions(sim, fresh);
    const std::vector<glm::vec3> v = sim.velocities(), w = fresh.velocities();
    const float h = sim.substep_length();
    for (std::size_t i = 0; i < v.size(); ++i) {
        INFO("particle " << i);
        CHECK(v[i] == w[i]);
        CHECK(glm::length(v[i]) < 9.81f * h);  // one substep from rest: below g h
    }
    sim.run_steps(10);
    fresh.run_steps(10);
    require_same_positions(sim, fresh);

    // wake() itself: velocities right after are those of a restart at rest, before any substep.
    MassSpring woken = asleep_cloth();
    MassSpring at_rest(woken.topology(), woken.state(), woken.settings());
    woken.wake();
    CHECK_FALSE(woken.asleep());
    const std::vector<glm::vec3> a = woken.velocities(), b = at_rest.velocities();
    const float g = glm::length(woken.settings().forces.gravity) * woken.substep_length();
    for (std::size_t i = 0; i < a.size(); ++i) {
        INFO("particle " << i);
        CHECK(a[i] == b[i]);
        CHECK(glm::length(a[i]) < g);
    }
}

TEST_CASE("sleep a copy of a sleeping cloth is asleep and steps identically", "[sleep]") {
    MassSpring sim = asleep_cloth();
    MassSpring copy = sim;
    CHECK(copy.asleep());
    CHECK(copy.asleep());
    CHECK(copy.change_stamp() == sim.change_stamp());
    sim.run_steps(10);
    copy.run_steps(10);
    CHECK(copy.asleep());
    require_same_positions(sim, copy);
    CHECK(copy.time() == sim.time());
    // Woken alike, they go on alike.
    test::edit_settings(sim, [&](SimulationSettings& edit) { edit.forces.wind = {2.0f, 0.0f, 1.0f}; });
    test::edit_settings(copy, [&](SimulationSettings& edit) { edit.forces.wind = {2.0f, 0.0f, 1.0f}; });
    sim.run_steps(30);
    copy.run_steps(30);
    CHECK_FALSE(copy.asleep());
    require_same_positions(sim, copy);
    // Assignment copies the sleep too.
    MassSpring assigned = build_simulation(settling_scene());
    assigned = asleep_cloth();
    CHECK(assigned.asleep());
}
