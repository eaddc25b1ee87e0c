// Penalty contact (colliders.contact = penalty; src/core/collision/penalty_contact.hpp): the force law against the
// analytic rest depth, energy conservation through a bounce, the fast and textbook paths bit for bit, and
// the stability bound that counts the contact stiffness.
#include "collision/penalty_contact.hpp"
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "clothsim/stability.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace clothsim;

namespace {

constexpr double kThickness = 0.005;  // m
constexpr double kStiffness = 1000.0;  // N/m
constexpr double kMass = 0.01;         // kg

// One free particle (a 1 x 1 cloth) at height y above the ground y = 0, with penalty contact and no sleep.
Scene particle_over_ground(double y, float damping, Integrator integrator, SolverMethod method, int substeps) {
    Scene s;
    s.cloth.rows = s.cloth.cols = 1;
    s.cloth.mass = static_cast<float>(kMass);
    s.cloth.origin = {0.0f, static_cast<float>(y), 0.0f};
    s.pins.preset = PinPreset::None;
    s.settings.springs.damping = damping;
    s.settings.colliders.contact = ContactModel::Penalty;
    s.settings.colliders.contact_stiffness = static_cast<float>(kStiffness);
    s.settings.colliders.thickness = static_cast<float>(kThickness);
    s.settings.integration.integrator = integrator;
    s.settings.integration.substeps = substeps;
    s.settings.solver.method = method;
    s.settings.solver.sleep_speed = 0.0f;
    return s;
}

// m: how deep the particle is in the ground's shell (thickness minus height).
double depth(const MassSpring& sim) { return double(sim.settings().colliders.thickness) - sim.state().position.y[0]; }

// A Cusick support (radius 0.09) standing on y = 0, top face at y = 0.5, frictionless; no ground.
constexpr CylinderCollider kSupport{{0.0f, 0.25f, 0.0f}, 0.09f, 0.5f};

// The undamped particle of particle_over_ground at (x, y, 0) over the support instead of the ground.
Scene particle_over_cylinder(double x, double y, int substeps) {
    Scene s = particle_over_ground(y, 0.0f, Integrator::Rk4, SolverMethod::Textbook, substeps);
    s.cloth.origin.x = static_cast<float>(x);
    test::collider(s.settings.colliders, "ground").enabled = false;
    test::collider(s.settings.colliders, "cylinder") = Collider{kSupport, 0.0f, true, {}};
    return s;
}

// m: how deep the particle is in the support's shell (thickness minus its distance to the solid).
double cylinder_depth(const MassSpring& sim) {
    const glm::dvec3 p = sim.state().position.get(0) - glm::dvec3(kSupport.center);
    const double side = std::max(std::hypot(p.x, p.z) - double(kSupport.radius), 0.0);
    const double face = std::max(std::abs(p.y) - 0.5 * double(kSupport.height), 0.0);
    return double(sim.settings().colliders.thickness) - std::hypot(side, face);
}


}  // namespace

TEST_CASE("penalty contact force and potential follow k p^3 / t^2 and k p^4 / (4 t^2)", "[contact_penalty]") {
    ColliderSettings colliders;
    colliders.contact = ContactModel::Penalty;
    colliders.contact_stiffness = static_cast<float>(kStiffness);
    colliders.thickness = static_cast<float>(kThickness);
    const double t = colliders.thickness;  // the float setting, in double
    const double p = 0.002;                 // m into the ground's shell
    State state = test::free_particles({{0.3f, 0.0f, 0.0f}}, static_cast<float>(kMass));
    state.position.set(0, {0.3, t - p, 0.0});
    DVec3Array force;
    force.resize(1);
    accumulate_contact_forces(state, colliders, force);
    const double expected = kStiffness * p * p * p / (t * t);
    CHECK(force.get(0).y == Approx(expected).epsilon(1e-12));
    CHECK(force.get(0).x == 0.0);
    CHECK(contact_potential_energy(state, colliders) == Approx(kStiffness * p * p * p * p / (4.0 * t * t)).epsilon(1e-12));
    // Outside the shell: no force, no energy; a pinned particle feels nothing.
    state.position.set(0, {0.3, t + 1e-6, 0.0});
    force.resize(1);
    accumulate_contact_forces(state, colliders, force);
    CHECK(force.get(0) == glm::dvec3(0.0));
    CHECK(contact_potential_energy(state, colliders) == 0.0);
    state.position.set(0, {0.3, 0.0, 0.0});
    state.pinned[0] = 1;
    accumulate_contact_forces(state, colliders, force);
    CHECK(force.get(0) == glm::dvec3(0.0));

    // The sphere pushes along its normal, the same depth as the projection's (radius + t - distance).
    test::collider(colliders, "ground").enabled = false;
    test::collider(colliders, "sphere") = Collider{SphereCollider{{0.0f, 0.0f, 0.0f}, 0.5f}, 0.0f, true, {}};
    state.pinned[0] = 0;
    const glm::dvec3 dir = glm::normalize(glm::dvec3(1.0, 2.0, -2.0));
    state.position.set(0, dir * (0.5 + t - p));
    force.resize(1);
    accumulate_contact_forces(state, colliders, force);
    const glm::dvec3 f = force.get(0);
    CHECK(glm::length(f) == Approx(expected).epsilon(1e-9));
    CHECK(glm::dot(f, dir) == Approx(glm::length(f)).epsilon(1e-12));

    // The cylinder pushes at the same depth (thickness less the distance to the solid) along the normal of
    // its nearest point: up from the top face, out from the side, and from a rim along the diagonal.
    test::collider(colliders, "sphere").enabled = false;
    // top face y = 0.5, side r = 0.5
    test::collider(colliders, "cylinder") = Collider{CylinderCollider{{0.0f, 0.0f, 0.0f}, 0.5f, 1.0f}, 0.0f, true, {}};
    const double top = 0.5 * double(test::cylinder(colliders).height), side = double(test::cylinder(colliders).radius);
    const glm::dvec3 around = glm::normalize(glm::dvec3(1.0, 0.0, -2.0));  // a direction around the axis
    const glm::dvec3 rim_dir = glm::normalize(glm::dvec3(3.0, 4.0, 0.0));
    struct Probe {
        const char* where;
        glm::dvec3 position, normal;
    };
    for (const Probe& probe : {Probe{"top face", {0.1, top + t - p, 0.2}, {0.0, 1.0, 0.0}},
                               Probe{"bottom face", {0.0, -top - t + p, -0.3}, {0.0, -1.0, 0.0}},
                               Probe{"side", (side + t - p) * around + glm::dvec3(0.0, 0.1, 0.0), around},
                               Probe{"rim", glm::dvec3(side, top, 0.0) + (t - p) * rim_dir, rim_dir}}) {
        INFO(probe.where);
        state.position.set(0, probe.position);
        force.resize(1);
        accumulate_contact_forces(state, colliders, force);
        CHECK(glm::length(force.get(0)) == Approx(expected).epsilon(1e-6));
        CHECK(glm::dot(force.get(0), probe.normal) == Approx(glm::length(force.get(0))).epsilon(1e-9));
        CHECK(contact_potential_energy(state, colliders) == Approx(kStiffness * p * p * p * p / (4.0 * t * t)).epsilon(1e-5));
    }
}

TEST_CASE("penalty contact: a damped particle settles at the depth where k p^3 / t^2 = m g", "[contact_penalty]") {
    // The analytic rest depth: p = (m g t^2 / k)^(1/3) = 1.349 mm here, 0.27 of the thickness.
    const double g = 9.81;
    const double rest = std::cbrt(kMass * g * kThickness * kThickness / kStiffness);
    struct Case {
        Integrator integrator;
        SolverMethod method;
        const char* name;
    };
    for (const Case& c : {Case{Integrator::Verlet, SolverMethod::Fast, "verlet, fast"},
                          Case{Integrator::Verlet, SolverMethod::Textbook, "verlet, textbook"},
                          Case{Integrator::Rk4, SolverMethod::Textbook, "rk4"}}) {
        INFO(c.name);
        // Released at rest on the shell (p = 0) with damping 20 1/s: the contact rings at about 150 rad/s and
        // decays as e^(-10 t), to 1e-9 of its swing in 2 s.
        MassSpring sim = build_simulation(particle_over_ground(kThickness, 20.0f, c.integrator, c.method, 10));
        REQUIRE(sim.plan().contact);
        sim.run_steps(150);  // 2.5 s
        INFO("depth " << depth(sim) << " m, analytic " << rest << " m");
        CHECK(std::fabs(depth(sim) - rest) < 1e-3 * rest);
        CHECK(sim.velocities()[0].y == Approx(0.0).margin(1e-6));
    }
}

TEST_CASE("penalty contact: an undamped bounce conserves total energy, to RK4's order in the substep",
          "[contact_penalty]") {
    // Dropped from 1 cm above the shell, the particle falls for 45 ms, goes 3.4 mm into the ground's shell
    // (0.69 of the thickness: k p^4 / (4 t^2) = m g (0.01 + p)) and comes back up to where it started. The
    // largest change of the total energy (kinetic, gravity and contact potential) over the run is RK4's error.
    const double drop = 0.01;
    auto worst_energy_error = [&](int substeps) {
        MassSpring sim = build_simulation(
            particle_over_ground(kThickness + drop, 0.0f, Integrator::Rk4, SolverMethod::Textbook, substeps));
        const double e0 = sim.energy().total();
        double worst = 0.0, deepest = 0.0, contact_energy = 0.0, highest_after = -1.0;
        for (int step = 0; step < 9; ++step) {  // 0.15 s: down, through the contact, back up to the top
            for (int i = 0; i < substeps; ++i) {
                sim.substep();
                const Energy e = sim.energy();
                worst = std::max(worst, std::fabs(e.total() - e0));
                deepest = std::max(deepest, depth(sim));
                contact_energy = std::max(contact_energy, e.contact_potential);
                if (deepest > 0.0) highest_after = std::max(highest_after, -depth(sim));
            }
        }
        INFO(substeps << " substeps per step: deepest " << deepest << " m, contact energy " << contact_energy
                      << " J, height reached after it " << highest_after << " m, worst energy error " << worst
                      << " J of " << e0 << " J");
        CHECK(deepest > 0.6 * kThickness);  // it went deep into the shell ...
        CHECK(deepest < kThickness);        // ... without passing the surface
        CHECK(contact_energy > 0.9 * kMass * 9.81 * drop);  // the fall's energy went into the contact
        CHECK(highest_after > 0.9 * drop);  // and came back out of it: it bounced
        return worst / std::fabs(e0);
    };
    const double coarse = worst_energy_error(16), fine = worst_energy_error(32), finer = worst_energy_error(64);
    INFO("relative energy error at h = 1.04, 0.52, 0.26 ms: " << coarse << ", " << fine << ", " << finer);
    CHECK(finer < 1e-6);
    CHECK(fine < coarse / 8.0);  // RK4: 1/16 or better per halving; at least 1/8 asked
    CHECK(finer < fine / 8.0);
}

TEST_CASE("penalty contact: an undamped bounce on the cylinder conserves total energy, on the top face and at the rim",
          "[contact_penalty]") {
    // As on the ground: dropped from 1 cm above the shell, onto the support's top face (a plane, as the
    // ground), and just beside its rim (0.001 m outside the side: its shell there is round, and the push
    // turns the particle outward; it leaves the shell before it falls below the top face's plane).
    const double drop = 0.01;
    const double top = double(kSupport.center.y) + 0.5 * double(kSupport.height);
    struct Case {
        const char* where;
        double x;
        bool crosses;  // falls below the top face's plane while in the shell
    };
    for (const Case& c : {Case{"top face", 0.03, false}, Case{"rim", double(kSupport.radius) + 0.001, false},
                          Case{"rim, then down the side", double(kSupport.radius) + 0.002, true}}) {
        INFO(c.where);
        auto worst_energy_error = [&](int substeps) {
            MassSpring sim = build_simulation(particle_over_cylinder(c.x, top + kThickness + drop, substeps));
            REQUIRE(sim.plan().contact);
            const double e0 = sim.energy().total();
            double worst = 0.0, deepest = 0.0, contact_energy = 0.0;
            for (int step = 0; step < 9; ++step) {  // 0.15 s: down, through the contact, back out
                for (int i = 0; i < substeps; ++i) {
                    sim.substep();
                    const Energy e = sim.energy();
                    worst = std::max(worst, std::fabs(e.total() - e0));
                    deepest = std::max(deepest, cylinder_depth(sim));
                    contact_energy = std::max(contact_energy, e.contact_potential);
                }
            }
            INFO(substeps << " substeps per step: deepest " << deepest << " m, contact energy " << contact_energy
                          << " J, worst energy error " << worst << " J of " << e0 << " J; ends at ("
                          << sim.position(0).x << ", " << sim.position(0).y << ")");
            CHECK(deepest > 0.3 * kThickness);  // it went into the shell ...
            CHECK(deepest < kThickness);        // ... without reaching the solid
            CHECK(contact_energy > 0.3 * kMass * 9.81 * drop);  // much of the fall's energy went into the contact
            CHECK(cylinder_depth(sim) < 0.0);   // and it came back out
            return worst / std::fabs(e0);
        };
        const double coarse = worst_energy_error(16), fine = worst_energy_error(32), finer = worst_energy_error(64);
        INFO("relative energy error at h = 1.04, 0.52, 0.26 ms: " << coarse << ", " << fine << ", " << finer);
        if (!c.crosses) {
            CHECK(finer < 1e-6);
            CHECK(fine < coarse / 8.0);  // RK4 (measured: 1/16 to 1/30 per halving)
            CHECK(finer < fine / 8.0);
        } else {
            // Where the rim's round shell meets the side's (the top face's plane) the depth's curvature jumps,
            // so the force's derivative does (penalty_contact.hpp): crossing there, RK4 loses its order, yet
            // the energy stays conserved. Measured: 8.7e-6, 1.8e-6, 1.4e-6.
            CHECK(coarse < 2e-5);
            CHECK(fine < coarse);
            CHECK(finer < fine);
        }
    }
}

TEST_CASE("penalty contact: fast and textbook solvers give bit-identical drapes", "[contact_penalty]") {
    Scene scene = per_spring_scene("drape-sphere");  // 38 substeps a step keep the textbook run short
    scene.settings.colliders.contact = ContactModel::Penalty;
    scene.cloth.origin.y = 0.87f;  // just above the sphere's shell: contact from the first steps
    scene.settings.solver.sleep_speed = 0.0f;
    auto run = [&](SolverMethod method) {
        Scene s = scene;
        s.settings.solver.method = method;
        s.settings.solver.threads = 2;
        MassSpring sim = build_simulation(s);
        REQUIRE(sim.fast_solver_available());
        sim.run_steps(20);
        return sim;
    };
    const MassSpring fast = run(SolverMethod::Fast);
    const MassSpring textbook = run(SolverMethod::Textbook);
    CHECK(fast.plan().path == StepPath::FastVerlet);
    CHECK(textbook.plan().path == StepPath::TextbookVerlet);
    CHECK(fast.energy().contact_potential > 0.0);  // the cloth is on the sphere
    CHECK(fast.all_finite());
    CHECK(test::bit_identical(fast, textbook));

    // The same with a cylinder in the sphere's place, its top face where the sphere's top is.
    test::collider(scene.settings.colliders, "sphere").enabled = false;
    test::collider(scene.settings.colliders, "cylinder") = Collider{CylinderCollider{{0.0f, 0.425f, 0.0f}, 0.3f, 0.85f}, 0.0f, true, {}};
    const MassSpring fast_cylinder = run(SolverMethod::Fast);
    const MassSpring textbook_cylinder = run(SolverMethod::Textbook);
    CHECK(fast_cylinder.energy().contact_potential > 0.0);  // the cloth is on the cylinder
    CHECK(fast_cylinder.all_finite());
    CHECK(test::bit_identical(fast_cylinder, textbook_cylinder));
}

TEST_CASE("penalty contact: the stability limit counts 3 k_c per enabled collider", "[contact_penalty]") {
    // Sphere and ground enabled; per spring, so every particle has the mass m below (a material's lumped
    // masses differ at the edges, and the Gershgorin row that bounds the limit may change with the contact).
    const MassSpring sim = build_simulation(per_spring_scene("drape-sphere"));
    SimulationSettings settings = sim.settings();
    const StabilityLimit projection = stability_limit(sim.topology(), sim.state(), settings);
    settings.colliders.contact = ContactModel::Penalty;
    settings.colliders.contact_stiffness = 2000.0f;
    const StabilityLimit penalty = stability_limit(sim.topology(), sim.state(), settings);
    const double m = sim.state().mass[0];
    const double added = 2 * 3.0 * 2000.0 / m;  // two colliders
    CHECK(penalty.omega_gershgorin * penalty.omega_gershgorin ==
          Approx(projection.omega_gershgorin * projection.omega_gershgorin + added).epsilon(1e-9));
    CHECK(penalty.omega_plane_wave * penalty.omega_plane_wave ==
          Approx(projection.omega_plane_wave * projection.omega_plane_wave + added).epsilon(1e-9));
    CHECK(penalty.critical_substep < projection.critical_substep);
    CHECK(penalty.bound == StabilityBound::Springs);  // explicit: the contact adds to the springs' bound

    // Implicit Euler takes the contact explicitly: no longer unconditionally stable, w_c h < 2.
    settings.integration.integrator = Integrator::ImplicitEuler;
    const StabilityLimit implicit = stability_limit(sim.topology(), sim.state(), settings);
    CHECK_FALSE(implicit.unconditionally_stable);
    CHECK(implicit.critical_substep == Approx(2.0 / std::sqrt(added)).epsilon(1e-9));
    CHECK(implicit.bound == StabilityBound::Contact);
    // XPBD's damping limit 2 / c against the contact's: the smaller one is named.
    settings.integration.integrator = Integrator::Xpbd;
    settings.springs.damping = 0.5f;  // 4 s: far above the contact's limit
    CHECK(stability_limit(sim.topology(), sim.state(), settings).bound == StabilityBound::Contact);
    settings.springs.damping = static_cast<float>(10.0 * std::sqrt(added));  // 2 / c well below it
    CHECK(stability_limit(sim.topology(), sim.state(), settings).bound == StabilityBound::Damping);
    settings.integration.integrator = Integrator::ImplicitEuler;
    settings.springs.damping = sim.settings().springs.damping;
    settings.colliders.contact = ContactModel::Projection;
    CHECK(stability_limit(sim.topology(), sim.state(), settings).unconditionally_stable);

    // The cylinder counts as one more collider: 3 k_c more.
    settings.integration.integrator = Integrator::Verlet;
    settings.colliders.contact = ContactModel::Penalty;
    test::collider(settings.colliders, "cylinder").enabled = true;
    const StabilityLimit three = stability_limit(sim.topology(), sim.state(), settings);
    CHECK(three.omega_gershgorin * three.omega_gershgorin ==
          Approx(projection.omega_gershgorin * projection.omega_gershgorin + 1.5 * added).epsilon(1e-9));
    CHECK(three.critical_substep < penalty.critical_substep);
}

TEST_CASE("penalty contact: a drape at the predicted limit stays finite and out of the sphere", "[contact_penalty]") {
    // The bound is what auto substeps use; at 0.9 of it the stiffest drape (10x the default stiffness) runs.
    Scene scene = per_spring_scene("drape-sphere");
    scene.cloth.rows = scene.cloth.cols = 16;
    scene.settings.colliders.contact = ContactModel::Penalty;
    scene.settings.colliders.contact_stiffness = 10000.0f;
    MassSpring sim = build_simulation(scene);
    const StabilityLimit limit = stability_limit(sim);
    const int substeps = auto_substeps(limit, scene.settings.integration.dt, 0.9f);
    test::edit_settings(sim, [&](SimulationSettings& s) { s.integration.substeps = substeps; });
    sim.run_steps(90);  // 1.5 s: falls onto the sphere and drapes
    REQUIRE(sim.all_finite());
    const SphereCollider& sphere = test::sphere(scene.settings.colliders);
    double closest = 1e9;
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        closest = std::min(closest, static_cast<double>(signed_distance(sphere, sim.position(i))));
    }
    INFO(substeps << " substeps per step; closest particle " << closest << " m from the sphere's surface");
    CHECK(closest > 0.0);                                                 // none went through the surface
    CHECK(closest < scene.settings.colliders.thickness);                  // and some lie on it
}
