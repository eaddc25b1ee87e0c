// MassSpring as a whole: statics, conservation laws, pins, determinism and the step bookkeeping.
#include "support.hpp"

#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstring>
#include <random>

using namespace clothsim;

TEST_CASE("mass_spring hanging 1 x N chain settles to the static elongation N(N+1) m g / (2k)", "[mass_spring]") {
    for (int n : {1, 5, 12}) {  // free particles below the pinned top one
        const float m = 0.02f, k = 30.0f, spacing = 0.1f, g = 9.81f;
        Scene s = test::chain(n + 1, spacing, m, k);
        s.pins.particles = {{0, 0}};
        s.settings.forces.gravity = {0.0f, -g, 0.0f};
        s.settings.springs.damping = 4.0f;
        s.settings.integration.dt = 1.0f / 60.0f;
        s.settings.integration.substeps = 20;
        s.settings.solver.sleep_speed = 0.0f;  // the limit itself, not where sleeping would freeze the approach
        MassSpring sim = build_simulation(s);
        sim.run_steps(60 * 20);  // 20 s: many times the slowest mode's decay time 2/c
        const double length = -sim.position(static_cast<std::size_t>(n)).y;
        const double elongation = length - spacing * n;
        const double expected = n * (n + 1) * m * g / (2.0 * k);
        INFO(n << " free particles: elongation " << elongation << " m, expected " << expected << " m");
        CHECK(elongation == Approx(expected).epsilon(1e-3));
        // Each spring j (from the top) carries the weight of the n - j + 1 particles below it.
        for (int j = 1; j <= n; ++j) {
            const double stretch = sim.position(j - 1).y - sim.position(j).y - spacing;
            CHECK(stretch == Approx((n - j + 1) * m * g / k).epsilon(2e-3));
        }
    }
}

TEST_CASE("mass_spring total momentum of a free cloth with springs only stays constant", "[mass_spring]") {
    Scene s;
    s.cloth.rows = 9;
    s.cloth.cols = 7;
    s.pins.preset = PinPreset::None;
    s.settings.forces.gravity = glm::vec3(0.0f);
    s.settings.springs.damping = 0.0f;
    test::collider(s.settings.colliders, "ground").enabled = false;
    MassSpring sim = build_simulation(s);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> jitter(-0.02f, 0.02f), speed(-1.0f, 1.0f);
    double speed_scale = 0.0;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const glm::vec3 v(speed(rng), speed(rng), speed(rng));
        sim.set_particle(i, sim.position(i) + glm::vec3(jitter(rng), jitter(rng), jitter(rng)), v);
        speed_scale += sim.particle(i).mass * glm::length(v);
    }
    const glm::vec3 p0 = sim.momentum();
    sim.run_steps(60);  // 1 s, 1500 substeps
    const glm::vec3 p1 = sim.momentum();
    INFO("momentum before (" << p0.x << ", " << p0.y << ", " << p0.z << "), after (" << p1.x << ", " << p1.y << ", "
                             << p1.z << "), scale " << speed_scale);
    CHECK(glm::length(p1 - p0) < 1e-5 * speed_scale);
    CHECK(glm::length(p0) > 1e-3 * speed_scale);  // the test is not trivially zero
}

TEST_CASE("mass_spring pinned particles never move", "[mass_spring]") {
    for (const std::string& name : bundled_scene_names()) {
        Scene s = test::scene_for_loops(name);  // the stiff scenes on a coarser grid (support.hpp)
        MassSpring sim = build_simulation(s);
        const std::vector<std::size_t> pins = pinned_particles(s.cloth, s.pins);
        std::vector<glm::vec3> start;
        for (std::size_t i : pins) start.push_back(sim.position(i));
        for (int step = 0; step < 120 / test::kLoopShare; ++step) {
            sim.run_steps(1);
            for (std::size_t k = 0; k < pins.size(); ++k) REQUIRE(sim.position(pins[k]) == start[k]);
        }
    }
    // Pinning mid-run stops a particle where it is; unpinning lets it fall again.
    MassSpring sim = build_simulation(load_scene("hanging"));
    sim.run_steps(10);
    sim.set_pinned(500, true);
    const glm::vec3 held = sim.position(500);
    sim.run_steps(30);
    CHECK(sim.position(500) == held);
    // A moved pin (a grab) stays exactly where it is put and drags its neighbours along.
    const glm::vec3 neighbour = sim.position(501);
    sim.move_pinned(500, held + glm::vec3(0.0f, 0.0f, 0.3f));
    sim.run_steps(30);
    CHECK(sim.position(500) == held + glm::vec3(0.0f, 0.0f, 0.3f));
    CHECK(sim.position(501).z > neighbour.z + 0.1f);
    sim.set_pinned(500, false);
    sim.run_steps(30);
    CHECK(sim.position(500) != held + glm::vec3(0.0f, 0.0f, 0.3f));
    // move_pinned leaves free particles alone.
    const glm::vec3 free_particle = sim.position(10);
    sim.move_pinned(10, glm::vec3(5.0f));
    CHECK(sim.position(10) == free_particle);
}

TEST_CASE("mass_spring the same scene run twice gives bit-identical positions", "[mass_spring]") {
    for (const char* name : {"flag", "drape-sphere", "drape-cube"}) {
        MassSpring a = build_simulation(load_scene(name));
        MassSpring b = build_simulation(load_scene(name));
        a.run_steps(90);
        b.run_steps(90);
        const State& sa = a.state();
        const State& sb = b.state();
        REQUIRE(sa.size() == sb.size());
        CHECK(std::memcmp(sa.position.x.data(), sb.position.x.data(), sa.size() * sizeof(sa.position.x[0])) == 0);
        CHECK(std::memcmp(sa.position.y.data(), sb.position.y.data(), sa.size() * sizeof(sa.position.x[0])) == 0);
        CHECK(std::memcmp(sa.position.z.data(), sb.position.z.data(), sa.size() * sizeof(sa.position.x[0])) == 0);
    }
}

TEST_CASE("mass_spring a copy assigned over another simulation, or over a moved-from one, steps as the original",
          "[mass_spring]") {
    MassSpring original = build_simulation(load_scene("drape-sphere"));
    original.run_steps(10);
    MassSpring other = build_simulation(load_scene("flag"));  // another size: its storage is reused or regrown
    other = original;
    MassSpring moved = build_simulation(load_scene("hanging"));
    MassSpring taker = std::move(moved);
    moved = original;  // NOLINT(bugprone-use-after-move): assigning to a moved-from object is allowed
    original.run_steps(20);
    other.run_steps(20);
    moved.run_steps(20);
    for (const MassSpring* copy : {&other, &moved}) {
        REQUIRE(copy->state().size() == original.state().size());
        CHECK(copy->state().position == original.state().position);
        CHECK(copy->state().motion == original.state().motion);
    }
    CHECK(taker.state().size() > 0);
}

TEST_CASE("mass_spring positions into a kept array equal positions(), whatever the array held", "[mass_spring]") {
    MassSpring sim = build_simulation(load_scene("drape-sphere"));
    sim.run_steps(30);
    const std::vector<glm::vec3> fresh = sim.positions();
    REQUIRE(fresh.size() == sim.particle_count());
    for (std::size_t i = 0; i < fresh.size(); ++i) {
        REQUIRE(fresh[i] == glm::vec3(sim.state().position.get(i)));  // the double state rounded once
    }
    // Longer, shorter and empty arrays filled with NaN all end as the particles' positions.
    for (std::size_t start : {fresh.size() + 7, fresh.size() / 2, std::size_t{0}, fresh.size()}) {
        std::vector<glm::vec3> kept(start, glm::vec3(NAN));
        sim.positions(kept);
        REQUIRE(kept.size() == fresh.size());
        CHECK(std::memcmp(kept.data(), fresh.data(), fresh.size() * sizeof(glm::vec3)) == 0);
    }
    // An array of the right size is written in place, not reallocated (the renderer's frame).
    std::vector<glm::vec3> frame(fresh.size());
    const glm::vec3* memory = frame.data();
    sim.substep();
    sim.positions(frame);
    CHECK(frame.data() == memory);
    CHECK(frame == sim.positions());
    CHECK(frame != fresh);  // the cloth moved
}

TEST_CASE("mass_spring zero-length springs and coincident particles stay finite", "[mass_spring]") {
    Topology t;
    t.rows = 1;
    t.cols = 3;
    t.springs = {{0, 1, 0.0f, SpringKind::Structural},   // zero rest length: F = k d, fine at d = 0
                 {1, 2, 0.5f, SpringKind::Structural}};  // rest 0.5 but the ends coincide: no direction
    const State st = test::free_particles({glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)}, 1.0f);
    SimulationSettings settings;
    settings.forces.gravity = glm::vec3(0.0f);
    test::collider(settings.colliders, "ground").enabled = false;
    MassSpring sim(t, st, settings);
    sim.run_steps(10);
    CHECK(sim.all_finite());
    CHECK(std::isfinite(sim.energy().total()));
    // Once apart, the springs act again and the centre of mass stays put (internal forces only).
    sim.set_particle(0, {0.1f, 0.0f, 0.0f}, glm::vec3(0.0f));
    sim.run_steps(10);
    CHECK(sim.all_finite());
    CHECK(sim.position(0).x + sim.position(1).x + sim.position(2).x == Approx(0.1f).margin(1e-5));
    CHECK(sim.position(0).x != Approx(0.1f).margin(1e-3));
}

TEST_CASE("mass_spring changing dt mid-run keeps the velocity (no jump)", "[mass_spring]") {
    Scene s = test::chain(1, 1.0f, 1.0f, 0.0f);
    s.settings.forces.gravity = {0.0f, -9.81f, 0.0f};
    s.settings.integration.dt = 0.01f;
    MassSpring sim = build_simulation(s);
    sim.run_steps(50);  // t = 0.5 s
    test::edit_settings(sim, [&](SimulationSettings& edit) { edit.integration.dt = 0.0025f; });
    sim.run_steps(200);  // t = 1.0 s
    // Free fall is exact for Verlet: any velocity jump at the change would show here.
    CHECK(sim.position(0).y == Approx(-0.5 * 9.81).margin(1e-4));
    CHECK(sim.velocities()[0].y == Approx(-9.81).margin(1e-3));
}

TEST_CASE("drag_pin: the pin travels to its target over one step, at most a quarter spacing a substep", "[pin]") {
    Scene scene = load_scene("hanging");
    scene.settings.springs.tether_strain = 0.0f;  // no tethers: the pin goes anywhere (the next test has them)
    MassSpring sim = build_simulation(scene);
    sim.run_steps(2);
    std::size_t pin = 0;
    while (!sim.particle(pin).pinned) ++pin;
    const double spacing = sim.self_collision_spacing();
    const int substeps = sim.settings().integration.substeps;
    const glm::dvec3 start = sim.state().position.get(pin);
    // A short drag (1 cm): the pin goes there at a steady pace, 1 / substeps of the way each substep.
    const glm::vec3 near = glm::vec3(start) + glm::vec3(0.01f, 0.0f, 0.0f);
    sim.drag_pin(pin, near);
    REQUIRE(sim.pin_target(pin).has_value());
    glm::dvec3 last = start;
    for (int k = 0; k < substeps; ++k) {
        sim.substep();
        const glm::dvec3 x = sim.state().position.get(pin);
        CHECK(glm::length(x - last) == Approx(glm::length(glm::dvec3(near) - start) / substeps).epsilon(1e-3));
        last = x;
    }
    CHECK(glm::length(last - glm::dvec3(near)) < 1e-6);
    CHECK_FALSE(sim.pin_target(pin).has_value());
    // A long one (1 m, 30 spacings): a quarter spacing a substep, then it stops at the target.
    const glm::vec3 far = near + glm::vec3(0.0f, 0.0f, 1.0f);
    sim.drag_pin(pin, far);
    double longest = 0.0;
    int taken = 0;
    for (; taken < 1000 && sim.pin_target(pin); ++taken) {
        const glm::dvec3 before = sim.state().position.get(pin);
        sim.substep();
        longest = std::max(longest, glm::length(sim.state().position.get(pin) - before));
    }
    CHECK(longest == Approx(MassSpring::kPinStepPerSubstep * spacing).epsilon(1e-6));
    CHECK(taken == static_cast<int>(std::ceil(1.0 / (MassSpring::kPinStepPerSubstep * spacing))));
    CHECK(glm::length(sim.state().position.get(pin) - glm::dvec3(far)) < 1e-6);
    // Freed, a pin forgets where it was going.
    sim.drag_pin(pin, near);
    sim.set_pinned(pin, false);
    CHECK_FALSE(sim.pin_target(pin).has_value());
}

TEST_CASE("drag_pin: pins of hanging and curtain dragged fast, as a mouse does, never trip the guard", "[pin]") {
    for (const char* name : {"hanging", "curtain"}) {
        INFO(name);
        MassSpring sim = build_simulation(load_scene(name));
        std::vector<std::size_t> pins;
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            if (sim.particle(i).pinned) pins.push_back(i);
        }
        std::string log;
        REQUIRE(run_guarded(sim, 30, GuardSettings{}, log));
        for (const std::size_t pin : {pins.front(), pins.back()}) {
            // Each end pin: 0.6 m in 0.25 s (15 steps of 4 cm: 2.4 m/s), down and sideways, then back in 5 steps
            // (7 m/s); then 1 m in 10 steps (6 m/s) straight out.
            glm::vec3 target = sim.position(pin);
            for (int step = 0; step < 20; ++step) {
                target += step < 15 ? glm::vec3(0.03f, -0.02f, 0.015f) : glm::vec3(-0.09f, 0.06f, -0.045f);
                sim.drag_pin(pin, target);
                const bool ok = run_guarded(sim, 1, GuardSettings{}, log);
                INFO("step " << step << ": " << log);
                REQUIRE(ok);
            }
            for (int step = 0; step < 30; ++step) {
                if (step < 10) target += glm::vec3(0.07f, -0.07f, 0.0f);
                sim.drag_pin(pin, target);
                const bool ok = run_guarded(sim, 1, GuardSettings{}, log);
                INFO("out, step " << step << ": " << log);
                REQUIRE(ok);
            }
            CHECK(log.empty());  // no step was retried
            CHECK(max_strain(sim) < 1.0);
            CHECK(sim.all_finite());
            // No pin ends farther from another than (1 + tether_strain) x their rest distance with tethers, or
            // (1 + kPinDragStretch) x without.
            const double tether = sim.settings().springs.tether_strain;
            const double stretch = 1.0 + (tether > 0.0 ? tether : MassSpring::kPinDragStretch);
            const MassSpring rest = build_simulation(load_scene(name));
            for (std::size_t j : pins) {
                const double now = glm::length(sim.state().position.get(pin) - sim.state().position.get(j));
                const double at_rest = glm::length(rest.state().position.get(pin) - rest.state().position.get(j));
                CHECK(now <= stretch * at_rest * (1.0 + 1e-6));
            }
        }
    }
}
