#include "clothsim/reference.hpp"

#include "collision/colliders.hpp"
#include "clothsim/scene.hpp"
#include "model/forces.hpp"
#include "integrators/integrators.hpp"
#include "collision/penalty_contact.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace clothsim {

std::vector<glm::dvec3> run_double_rk4(const Scene& scene, double duration, double h) {
    // Whole substeps that end exactly at `duration`.
    const long long steps = std::max(1LL, std::llround(duration / h));
    h = duration / static_cast<double>(steps);
    // The builder gives the topology and the start; forces are then computed in double too.
    const MassSpring start = build_simulation(scene);
    State state = start.state();
    const std::size_t n = state.size();
    state.integrator = Integrator::Rk4;
    state.substep = h;
    const glm::dvec3 velocity(scene.cloth.velocity);
    for (std::size_t i = 0; i < n; ++i) {
        state.motion.set(i, state.pinned[i] ? glm::dvec3(0.0) : velocity * h);
    }
    const SimulationSettings& settings = scene.settings;
    const Topology& topology = start.topology();
    const double rest_area = start.rest_area();
    // The stages the simulation runs, from its own plan: wind, penalty contact (a force) or projection, soft clips.
    const StepPlan& plan = start.plan();
    const BasicForceFunction<double> forces = [&](const State& s, DVec3Array& out) {
        out.resize(s.size());
        accumulate_spring_forces(topology, s.position, settings.springs, out);
        if (plan.external_forces()) {
            DVec3Array external;
            external.resize(s.size());
            if (plan.wind) accumulate_wind_forces(topology, s, settings.forces, rest_area, external);
            if (plan.contact) accumulate_contact_forces(s, settings.colliders, external);
            if (plan.soft_clips) accumulate_soft_clip_forces(topology, s.position, external);
            for (std::size_t i = 0; i < s.size(); ++i) out.add(i, external.get(i));
        }
    };
    const BasicDynamics<double> dynamics{forces, forces, settings.forces.gravity, settings.springs.damping};
    for (long long s = 0; s < steps; ++s) {
        step_rk4(state, dynamics, h);
        if (plan.colliders) collide_all(state, settings.colliders);
        state.time += h;
    }
    std::vector<glm::dvec3> out(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = state.position.get(i);
    return out;
}

double cloth_size(const Scene& scene) { return std::max(scene.cloth.size.x, scene.cloth.size.y); }

ErrorNorms relative_error(const std::vector<glm::dvec3>& positions, const std::vector<glm::dvec3>& reference,
                          double size) {
    ErrorNorms e;
    double sum = 0.0;
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const double d = glm::length(positions[i] - reference[i]) / size;
        sum += d * d;
        e.max = std::max(e.max, d);
    }
    e.rms = positions.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(positions.size()));
    return e;
}

ErrorNorms relative_error(const MassSpring& sim, const std::vector<glm::dvec3>& reference, double size) {
    std::vector<glm::dvec3> p(sim.particle_count());
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = sim.state().position.get(i);
    return relative_error(p, reference, size);
}

Reference reference_solution(const Scene& scene, double duration, double first_substep, double tolerance,
                             int max_halvings) {
    Reference ref;
    double h = first_substep;
    std::vector<glm::dvec3> coarse = run_double_rk4(scene, duration, h);
    for (ref.halvings = 1; ref.halvings <= max_halvings; ++ref.halvings) {
        h *= 0.5;
        std::vector<glm::dvec3> fine = run_double_rk4(scene, duration, h);
        ref.halving_change = relative_error(coarse, fine, cloth_size(scene)).max;
        ref.positions = std::move(fine);
        ref.substep = h;
        if (ref.halving_change < tolerance) {
            ref.converged = true;
            break;
        }
        coarse = ref.positions;
    }
    return ref;
}

}  // namespace clothsim
