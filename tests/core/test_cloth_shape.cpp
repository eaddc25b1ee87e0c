// cloth.shape: a disc keeps the particles inside the grid's inscribed circle, on every solver path.
#include "scene/cloth_shape.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"

#include "every_kernel.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace clothsim;

namespace {

Scene disc_scene(int n, bool material) {
    Scene s = test::disc_specimen(n);
    // Held at its centre, as the Cusick tester's clamp discs hold the specimen.
    s.pins.particles = {{n / 2, n / 2}};
    s.settings.solver.sleep_speed = 0.0f;
    if (material) {
        s.material.enabled = true;
        s.material.density = 0.15f;
        s.material.stretch = glm::vec2(500.0f);
        s.material.shear = 20.0f;
        s.material.bending = glm::vec2(5e-6f);
    } else {
        s.cloth.mass = 0.01f;
        s.settings.springs.structural = glm::vec2(100.0f);
        s.settings.springs.shear = 10.0f;
        s.settings.springs.bending = glm::vec2(1.0f);
    }
    return s;
}

}  // namespace

TEST_CASE("cloth shape: a disc keeps the particles inside the inscribed circle and the cells they complete",
          "[cloth_shape]") {
    for (int n : {9, 16, 33}) {
        ClothSettings cloth;
        cloth.rows = cloth.cols = n;
        cloth.shape = ClothShape::Disc;
        const ShapeMask m = shape_mask(cloth);
        const double centre = 0.5 * (n - 1);
        std::size_t cells = 0;
        for (int r = 0; r < n; ++r) {
            for (int c = 0; c < n; ++c) {
                const double x = (c - centre) / centre, y = (r - centre) / centre;
                if (m.has_particle(r, c)) CHECK(x * x + y * y <= 1.0 + 1e-9);
                if (r + 1 < n && c + 1 < n) {
                    // A cell is in exactly when its four corners are inside the circle.
                    auto inside = [&](int rr, int cc) {
                        const double u = (cc - centre) / centre, v = (rr - centre) / centre;
                        return u * u + v * v <= 1.0 + 1e-9;
                    };
                    const bool all = inside(r, c) && inside(r, c + 1) && inside(r + 1, c) && inside(r + 1, c + 1);
                    CHECK(m.has_cell(r, c) == all);
                    cells += all;
                }
            }
        }
        CHECK(m.cell_count == cells);
        // The disc's area tends to pi R^2 from below (cells cut by the circle are left out).
        const double area = double(cells) / ((n - 1.0) * (n - 1.0));
        CHECK(area < 3.14159265 / 4.0);
        CHECK(area > 3.14159265 / 4.0 * (1.0 - 4.5 / (n - 1)));
        cloth.shape = ClothShape::Rectangle;
        CHECK(shape_mask(cloth).cell_count == static_cast<std::size_t>((n - 1) * (n - 1)));
    }
}

TEST_CASE("cloth shape: absent particles have no mass, springs, bends or triangles, the disc weighs density x area",
          "[cloth_shape]") {
    for (bool material : {true, false}) {
        const Scene s = disc_scene(24, material);
        const MassSpring sim = build_simulation(s);
        const State& st = sim.state();
        const ShapeMask m = shape_mask(s.cloth);
        double total = 0.0;
        for (std::size_t i = 0; i < st.size(); ++i) {
            INFO("particle " << i);
            CHECK((st.pinned[i] == kAbsent) == !m.particle[i]);
            if (!m.particle[i]) {
                CHECK(st.mass[i] == 0.0f);
                CHECK(st.inverse_mass[i] == 0.0f);
            }
            total += st.mass[i];
        }
        auto present = [&](std::uint32_t i) { return st.pinned[i] != kAbsent; };
        for (const Spring& sp : sim.topology().springs) CHECK((present(sp.a) && present(sp.b)));
        for (const Bend& b : sim.topology().bends) CHECK((present(b.a) && present(b.m) && present(b.b)));
        for (const auto& t : sim.topology().triangles) CHECK((present(t[0]) && present(t[1]) && present(t[2])));
        CHECK(sim.topology().triangles.size() == 2 * m.cell_count);
        if (material) CHECK(total == Approx(0.15 * sim.rest_area()).epsilon(1e-5));
        else CHECK(total == Approx(0.01).epsilon(1e-5));
    }
}

TEST_CASE("cloth shape: a disc runs on the fast solver bit for bit with the textbook solver, every kernel and thread "
          "count, and its absent particles never move", "[cloth_shape][fast_solver]") {
    for (bool material : {true, false}) {
        Scene s = disc_scene(27, material);
        s.settings.forces.wind = {0.5f, 0.0f, 1.0f};
        s.settings.integration.substeps = auto_substeps(stability_limit(build_simulation(s)), s.settings.integration.dt, 0.7f, 1);
        auto run = [&](SolverMethod method, int threads) {
            Scene t = s;
            t.settings.solver.method = method;
            t.settings.solver.threads = threads;
            MassSpring sim = build_simulation(t);
            REQUIRE(sim.fast_solver_available());
            sim.run_steps(15);
            return sim;
        };
        const MassSpring textbook = run(SolverMethod::Textbook, 1);
        REQUIRE(textbook.all_finite());
        const MassSpring start = build_simulation(s);
        for (std::size_t i = 0; i < start.particle_count(); ++i) {
            if (start.state().pinned[i] == kAbsent) CHECK(textbook.state().position.get(i) == start.state().position.get(i));
        }
        test::with_every_kernel([&] {
            for (int threads : test::thread_counts({1, 2})) {
                INFO((material ? "material" : "per spring") << ", kernel " << FastSolver::kernel_name() << ", "
                                                            << threads << " threads");
                CHECK(test::bit_identical(run(SolverMethod::Fast, threads), textbook));
            }
        });
    }
}

TEST_CASE("cloth shape: every integrator leaves a disc's absent particles where they are and stays finite",
          "[cloth_shape]") {
    for (Integrator integrator : {Integrator::Verlet, Integrator::SymplecticEuler, Integrator::Rk4,
                                  Integrator::ImplicitEuler, Integrator::Xpbd}) {
        Scene s = disc_scene(15, true);
        s.settings.integration.integrator = integrator;
        MassSpring sim = build_simulation(s);
        sim.set_substeps(auto_substeps(stability_limit(sim), s.settings.integration.dt, 0.5f, 4));
        const MassSpring start = sim;
        sim.run_steps(20);
        INFO(static_cast<int>(integrator));
        CHECK(sim.all_finite());
        bool moved = false;
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            if (sim.state().pinned[i] == kAbsent) CHECK(sim.state().position.get(i) == start.state().position.get(i));
            else if (sim.state().pinned[i] == 0) moved |= sim.state().position.get(i) != start.state().position.get(i);
        }
        CHECK(moved);  // the cloth itself falls
        // A user cannot pin, free or move an absent slot.
        const std::size_t corner = 0;
        REQUIRE(sim.state().pinned[corner] == kAbsent);
        sim.set_pinned(corner, false);
        sim.move_pinned(corner, glm::vec3(5.0f));
        CHECK(sim.state().pinned[corner] == kAbsent);
        CHECK(sim.state().position.get(corner) == start.state().position.get(corner));
    }
}

TEST_CASE("cloth shape: a disc too small to hold a whole cell is refused with a message", "[cloth_shape]") {
    CHECK_THROWS_WITH(parse_scene("[cloth]\nrows = 9\ncols = 3\nshape = \"disc\"\n", "d.toml"),
                      Catch::Contains("d.toml:4") && Catch::Contains("keeps no whole cell of the 9 x 3 grid"));
    Scene s = parse_scene("[cloth]\nrows = 9\ncols = 9\nshape = \"disc\"\n[material]\npreset = \"silk\"\n", "e.toml");
    CHECK_THROWS_WITH(apply_override(s, "cloth.cols=3"), Catch::Contains("--set cloth.cols=3"));
    CHECK(s.cloth.cols == 9);
    CHECK(shape_mask(s.cloth).cell_count > 0);
}
