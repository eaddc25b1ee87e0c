// XPBD's grid form (grid_xpbd.hpp) against its exact oracle (the list-order XPBD on the same elements listed in
// the grid's order), across kernels; and the physics it must keep: momentum, pins, convergence to the spring
// model as the substeps grow.
#include "every_kernel.hpp"
#include "integrators/grid_xpbd.hpp"
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "clothsim/strain.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <tuple>

using namespace clothsim;

namespace {

// The grid form's projection order (grid_xpbd.hpp) as a sort key of an element from particle a to b: its
// direction; for the directions down, whether it reaches from its band of rows into the next, and its band;
// then its row, its phase along the row, its column.
std::tuple<int, int, int, int, int, int> spring_key(const Topology& t, std::uint32_t a, std::uint32_t b) {
    int ra = static_cast<int>(a) / t.cols, ca = static_cast<int>(a) % t.cols;
    int rb = static_cast<int>(b) / t.cols, cb = static_cast<int>(b) % t.cols;
    if (rb < ra || (rb == ra && cb < ca)) std::swap(ra, rb), std::swap(ca, cb);
    const int dr = rb - ra, dc = cb - ca;
    constexpr int band_rows = GridXpbd::kBandRows;
    const int band = ra / band_rows;
    const int reaches = rb >= (band + 1) * band_rows ? 1 : 0;  // into the next band
    if (dr == 0 && dc == 1) return {0, 0, band, ra, ca % 2, ca};  // along the row, every second column
    if (dr == 1 && dc == 0) return {1, reaches, band, ra, 0, ca};  // down
    if (dr == 1 && dc == 1) return {2, reaches, band, ra, 0, ca};  // diagonal down right
    if (dr == 1 && dc == -1) return {3, reaches, band, ra, 0, ca}; // diagonal down left
    if (dr == 0 && dc == 2) return {4, 0, band, ra, ca % 3, ca};  // two apart along the row, every third column
    return {5, reaches, band, ra, 0, ca};                          // two apart down
}

// `sim`'s topology with its springs and bends listed in the grid form's order.
Topology in_grid_order(const MassSpring& sim) {
    Topology t = sim.topology();
    std::stable_sort(t.springs.begin(), t.springs.end(), [&](const Spring& x, const Spring& y) {
        return spring_key(t, x.a, x.b) < spring_key(t, y.a, y.b);
    });
    std::stable_sort(t.bends.begin(), t.bends.end(), [&](const Bend& x, const Bend& y) {
        return spring_key(t, std::min(x.a, x.b), std::min(x.a, x.b) + 2 * (std::max(x.a, x.b) - x.m)) <
               spring_key(t, std::min(y.a, y.b), std::min(y.a, y.b) + 2 * (std::max(y.a, y.b) - y.m));
    });
    return t;
}

// Whether two simulations hold equal positions and motion (== per coordinate).
bool same_state(const MassSpring& a, const MassSpring& b) {
    const State& sa = a.state();
    const State& sb = b.state();
    return sa.position == sb.position && sa.motion == sb.motion;
}

Scene xpbd_scene(Scene s, int rows, int cols, int substeps) {
    s.cloth.rows = rows;
    s.cloth.cols = cols;
    s.settings.integration.integrator = Integrator::Xpbd;
    s.settings.integration.substeps = substeps;
    s.settings.solver.method = SolverMethod::Fast;
    return s;
}

double centroid_distance(const State& s, glm::dvec3 reference) {
    glm::dvec3 sum(0.0);
    double mass = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        sum += static_cast<double>(s.mass[i]) * s.position.get(i);
        mass += s.mass[i];
    }
    return glm::length(sum / mass - reference);
}

}  // namespace

TEST_CASE("grid XPBD is the list-order XPBD on its elements listed in the grid's order, bit for bit, with every "
          "kernel and thread count", "[xpbd][grid]") {
    // Skip-one springs (per spring), bends with half-weight edges and warp and weft (material), a disc's absent
    // slots; pins, gravity, damping, wind, a collider. Neither side a multiple of a vector's width.
    Scene material = load_scene("hanging");
    material.material.stretch = {3000.0f, 1500.0f};
    material.material.bending = {2e-5f, 5e-6f};
    material.settings.forces.wind = {1.0f, 0.0f, 3.0f};
    // Stretch curves whose knots the hanging cloth passes (stretch_curve.hpp: the secant compliance).
    Scene curved = material;
    curved.material.stretch_curve.u = {{0.0005f, 3.0f}, {0.002f, 8.0f}};
    curved.material.stretch_curve.v = {{0.001f, 2.5f}};
    curved.material.explicit_fields |= kMaterialStretchCurve;
    derive_springs(curved);
    Scene disc = test::disc_specimen(15);
    test::collider(disc.settings.colliders, "sphere").enabled = true;
    test::sphere(disc.settings.colliders).center = {0.0f, 0.8f, 0.0f};
    test::sphere(disc.settings.colliders).radius = 0.09f;
    const std::pair<const char*, Scene> cases[] = {
        {"per-spring hanging", xpbd_scene(per_spring_scene("hanging"), 13, 11, 8)},
        {"per-spring drape-sphere", xpbd_scene(per_spring_scene("drape-sphere"), 10, 17, 4)},
        {"material hanging", xpbd_scene(material, 12, 19, 8)},
        {"material disc", xpbd_scene(disc, 15, 15, 8)},
        {"material hanging, curved", xpbd_scene(curved, 12, 19, 8)},
        // Three bands of rows and a part of one: the rows that reach into the next band come last.
        {"per-spring hanging, tall", xpbd_scene(per_spring_scene("hanging"), 2 * GridXpbd::kBandRows + 9, 9, 8)},
        {"material hanging, tall", xpbd_scene(material, 3 * GridXpbd::kBandRows + 1, 10, 8)},
        // Rows whose passes along them run several blocks of four vector lanes and a remainder.
        {"material hanging, wide", xpbd_scene(material, 7, 43, 8)},
        // The bundled scene that runs XPBD, on the grid of the simulation loops (support.hpp).
        {"stiff-drape", test::scene_for_loops("stiff-drape")},
    };
    for (const auto& [name, scene] : cases) {
        const MassSpring built = build_simulation(scene);
        SimulationSettings textbook_settings = built.settings();  // a material's springs as derived on the grid
        textbook_settings.solver.method = SolverMethod::Textbook;
        MassSpring oracle(in_grid_order(built), built.state(), textbook_settings);
        oracle.run_steps(40);
        REQUIRE(oracle.all_finite());
        test::with_every_kernel([&] {
            for (int threads : {1, 2, 3}) {
                Scene threaded = scene;
                threaded.settings.solver.threads = threads;
                MassSpring grid = build_simulation(threaded);
                grid.run_steps(40);
                INFO(name << " with the " << FastSolver::kernel_name() << " kernel, " << threads << " threads");
                CHECK(same_state(grid, oracle));
                // The residual the panel and --json report: the same constraints and multipliers, summed in
                // another order.
                CHECK(grid.last_solver_residual() == Approx(oracle.last_solver_residual()).epsilon(1e-9));
                CHECK(grid.last_solver_residual() > 0.0);
            }
        });
        // And it is another order than the list's: the list-order XPBD differs (the test above means something).
        Scene list = scene;
        list.settings.solver.method = SolverMethod::Textbook;
        MassSpring listed = build_simulation(list);
        listed.run_steps(40);
        INFO(name);
        CHECK_FALSE(same_state(listed, oracle));
    }
}

TEST_CASE("grid XPBD reports the list order's residual on the bundled stiff-drape at full width, with every kernel",
          "[xpbd][grid]") {
    // 128 columns: the vector loops' full width and remainders differ from the small grids above (GCC 12 once
    // summed a wrong constraint violation in the bends along a row there, while every position was right).
    Scene scene = load_scene("stiff-drape");
    scene.cloth.rows = 24;  // the full width, fewer rows: the list-order oracle is slow
    scene.settings.solver.threads = 1;
    const MassSpring built = build_simulation(scene);
    SimulationSettings textbook_settings = built.settings();
    textbook_settings.solver.method = SolverMethod::Textbook;
    MassSpring oracle(in_grid_order(built), built.state(), textbook_settings);
    oracle.run_steps(3);
    REQUIRE(oracle.last_solver_residual() > 0.0);
    test::with_every_kernel([&] {
        MassSpring grid = build_simulation(scene);
        grid.run_steps(3);
        INFO("the " << FastSolver::kernel_name() << " kernel");
        CHECK(same_state(grid, oracle));
        CHECK(grid.last_solver_residual() == Approx(oracle.last_solver_residual()).epsilon(1e-9));
    });
}

TEST_CASE("grid XPBD keeps the centre of mass of a free cloth without external forces", "[xpbd][grid]") {
    // Every projection moves its particles by mass-weighted opposite amounts: no net force, so a cloth
    // released stretched and spinning keeps its centre of mass where its initial momentum takes it (here: 0).
    Scene s = xpbd_scene(per_spring_scene("hanging"), 9, 14, 4);
    s.pins.preset = PinPreset::None;
    s.pins.particles.clear();
    s.settings.forces.gravity = {0.0f, 0.0f, 0.0f};
    s.settings.springs.damping = 0.0f;
    test::collider(s.settings.colliders, "ground").enabled = false;
    MassSpring sim = build_simulation(s);
    // Stretch it unevenly (a shear and a bulge), at rest.
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const glm::vec3 p = sim.position(i);
        sim.set_particle(i, p * glm::vec3(1.3f, 1.0f, 0.8f) + glm::vec3(0.1f * p.z, 0.05f * p.x * p.x, 0.0f),
                         glm::vec3(0.0f));
    }
    glm::dvec3 start(0.0);
    double mass = 0.0;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        start += static_cast<double>(sim.state().mass[i]) * sim.state().position.get(i);
        mass += sim.state().mass[i];
    }
    start /= mass;
    sim.run_steps(60);  // 1 s
    REQUIRE(sim.all_finite());
    INFO("centre of mass moved by " << centroid_distance(sim.state(), start) << " m");
    CHECK(centroid_distance(sim.state(), start) < 1e-12);
    // And the springs did their work: the stretch fell from 30% towards rest.
    const double strain = max_strain(sim.topology(), sim.state().position, SpringKind::Structural);
    INFO("largest structural strain " << strain);
    CHECK(strain < 0.1);
}
