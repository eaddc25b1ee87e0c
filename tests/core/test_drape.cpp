// The Cusick drape test's figures from a cloth's shadow (drape.hpp), on shapes whose shadow is known exactly.
#include "clothsim/drape.hpp"
#include "clothsim/scene.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace clothsim;

namespace {

MassSpring specimen(int n = 65) { return build_simulation(test::disc_specimen(n)); }

// Moves every particle of the ring outside `support` (polar r, phi about the axis) to the horizontal radius
// support + (r - support) spread(phi), dropping the rest of its length straight down.
template <class Spread>
void fold(MassSpring& sim, double support, Spread spread) {
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        if (sim.state().pinned[i] == kAbsent) continue;
        const glm::dvec3 p = sim.state().position.get(i);
        const double r = std::hypot(p.x, p.z), phi = std::atan2(p.z, p.x);
        if (r <= support) continue;
        const double out = support + (r - support) * spread(phi);
        sim.set_particle(i, glm::vec3(glm::dvec3(out * std::cos(phi), p.y - (r - out), out * std::sin(phi))),
                         glm::vec3(0.0f));
    }
}

}  // namespace

TEST_CASE("drape: a flat specimen has a drape coefficient of 1 and no folds", "[drape]") {
    for (int n : {25, 33, 41, 65, 129}) {
        const MassSpring sim = specimen(n);
        const DrapeFigures d = measure_drape(sim, glm::dvec3(0.0), 0.09);
        INFO(n << " particles a side: outline " << d.outline_min << " to " << d.outline_max << " m");
        CHECK(d.specimen_area == Approx(sim.rest_area()));
        CHECK(d.shadow_area == Approx(d.specimen_area).epsilon(0.005));
        CHECK(d.drape_coefficient == Approx(1.0).epsilon(0.01));
        CHECK(d.folds == 0);  // the grid's stair-stepped outline is no fold
    }
}

TEST_CASE("drape: a ring hanging straight down leaves the support's shadow: a drape coefficient of 0", "[drape]") {
    MassSpring sim = specimen();
    fold(sim, 0.09, [](double) { return 0.0; });
    const DrapeFigures d = measure_drape(sim, glm::dvec3(0.0), 0.09);
    // The shadow is the specimen's part inside the support, a polygon just inside the circle: within 2%.
    CHECK(d.drape_coefficient == Approx(0.0).margin(0.02));
    CHECK(d.folds == 0);
}

TEST_CASE("drape: six folds of known outline give their exact area and count", "[drape]") {
    for (int nodes : {4, 6, 9}) {
        MassSpring sim = specimen();
        const double support = 0.09;
        auto spread = [&](double phi) { return 0.55 + 0.35 * std::cos(nodes * phi); };
        fold(sim, support, spread);
        // The shadow's outline is R(phi) = support + (R_edge - support) spread(phi) with R_edge the specimen's
        // outline; its area is the integral of R^2 / 2. R_edge is the discrete disc's (the cloth's own area).
        const double edge = std::sqrt(sim.rest_area() / std::numbers::pi);
        double area = 0.0;
        const int n = 100000;
        for (int k = 0; k < n; ++k) {
            const double phi = 2.0 * std::numbers::pi * (k + 0.5) / n;
            const double r = support + (edge - support) * spread(phi);
            area += 0.5 * r * r * 2.0 * std::numbers::pi / n;
        }
        const DrapeFigures d = measure_drape(sim, glm::dvec3(0.0), support);
        const double expected = (area - std::numbers::pi * support * support) / (sim.rest_area() - std::numbers::pi * support * support);
        INFO(nodes << " nodes: DC " << d.drape_coefficient << " against " << expected);
        CHECK(d.drape_coefficient == Approx(expected).margin(0.02));
        CHECK(d.folds == nodes);
    }
}

TEST_CASE("drape: the bundled cusick scene settles to folds and a drape coefficient between hanging and flat",
          "[drape][convergence]") {
    Scene s = load_scene("cusick");
    s.settings.solver.threads = 1;
    MassSpring sim = build_simulation(s);
    sim.run_steps(180);  // 3 s: settled to a kinetic energy of 1e-7 J
    REQUIRE(sim.all_finite());
    const CylinderCollider& c = test::cylinder(s.settings.colliders);
    const DrapeFigures d = measure_drape(sim, glm::dvec3(c.center), c.radius);
    INFO("DC " << d.drape_coefficient << ", folds " << d.folds);
    CHECK(d.drape_coefficient > 0.3);
    CHECK(d.drape_coefficient < 0.95);
    CHECK(d.folds >= 3);
    CHECK(d.folds <= 12);
}
