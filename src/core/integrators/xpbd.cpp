#include "integrators/integrators.hpp"
#include "integrators/integrator_step.hpp"

#include "integrators/xpbd_projection.hpp"
#include "model/forces.hpp"
#include "model/gaussian_curvature.hpp"

#include <glm/geometric.hpp>

#include <cmath>

namespace clothsim {

void step_xpbd(State& state, const Dynamics& dynamics, const Topology& topology, const SpringSettings& springs,
               double h, XpbdMultipliers& multipliers) {
    const std::size_t n = state.size();
    state.substep = h;
    // External accelerations only (gravity, wind, damping): the springs are constraints here.
    Vec3Array wind;
    DVec3Array a;
    wind.resize(n);
    dynamics.external(state, wind);
    accumulate_gaussian_forces(topology, state.position, springs, wind);  // a force, not a constraint
    accelerations(state, wind, dynamics.gravity, dynamics.damping, a);
    const DVec3Array start = state.position;
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) continue;
        state.position.add(i, state.motion.get(i) + a.get(i) * (h * h));  // x + h (v + h a)
    }
    // One Gauss-Seidel pass over the springs, then the bends, then the hinges, then the membranes, in list order
    // (xpbd_projection.hpp). GridXpbd (grid_xpbd.hpp) and ColouredXpbd (coloured_xpbd.hpp) do the same
    // arithmetic in other orders.
    multipliers.spring.assign(topology.springs.size(), 0.0);
    multipliers.bend.assign(topology.bends.size(), glm::dvec3(0.0));
    multipliers.hinge.assign(topology.hinges.size(), glm::dvec3(0.0));
    multipliers.membrane.assign(topology.membranes.size(), glm::dvec3(0.0));
    double violation2 = 0.0;
    for (std::size_t j = 0; j < topology.springs.size(); ++j) {
        const double k = stiffness_of(springs, topology.springs[j]);
        if (k != 0.0) {
            violation2 += project_spring(state, topology.springs[j], k, h, multipliers.spring[j],
                                         curve_of(springs, topology.springs[j]));
        }
    }
    for (std::size_t j = 0; j < topology.bends.size(); ++j) {
        const double k = stiffness_of(springs, topology.bends[j]);
        if (k != 0.0) violation2 += project_bend(state, topology.bends[j], k, h, multipliers.bend[j]);
    }
    for (std::size_t j = 0; j < topology.hinges.size(); ++j) {
        const double k = stiffness_of(springs, topology.hinges[j]);
        if (k != 0.0) violation2 += project_hinge(state, topology.hinges[j], k, h, multipliers.hinge[j]);
    }
    if (!topology.membranes.empty()) {
        const MembraneTensor c = membrane_tensor(springs);
        for (std::size_t j = 0; j < topology.membranes.size(); ++j) {
            violation2 += project_membrane(state, topology.membranes[j], c, springs, h, multipliers.membrane[j]);
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        state.motion.set(i, state.pinned[i] ? glm::dvec3(0.0) : state.position.get(i) - start.get(i));
    }
    multipliers.substep = h;
    multipliers.initial_violation = std::sqrt(violation2);
}

double xpbd_residual(const DVec3Array& position, const Topology& topology, const SpringSettings& springs,
                     const XpbdMultipliers& multipliers) {
    if (multipliers.spring.size() != topology.springs.size() || multipliers.bend.size() != topology.bends.size() ||
        multipliers.hinge.size() != topology.hinges.size() || multipliers.membrane.size() != topology.membranes.size()) {
        return 0.0;  // no XPBD substep yet
    }
    const double h2 = multipliers.substep * multipliers.substep;
    double residual2 = 0.0;
    for (std::size_t j = 0; j < topology.springs.size(); ++j) {
        const Spring& s = topology.springs[j];
        const double k = stiffness_of(springs, s);
        if (k == 0.0) continue;
        const double c = glm::length(position.get(s.b) - position.get(s.a)) - s.rest_length;
        const double r = spring_residual(c, multipliers.spring[j], k, h2, curve_of(springs, s), s.rest_length);
        residual2 += r * r;
    }
    for (std::size_t j = 0; j < topology.bends.size(); ++j) {
        const Bend& b = topology.bends[j];
        const double k = stiffness_of(springs, b);
        if (k == 0.0) continue;
        const glm::dvec3 r = bend_difference(position, b) + multipliers.bend[j] / (k * h2);
        residual2 += glm::dot(r, r);
    }
    for (std::size_t j = 0; j < topology.hinges.size(); ++j) {
        const Hinge& hinge = topology.hinges[j];
        const double k = stiffness_of(springs, hinge);
        if (k == 0.0) continue;
        const glm::dvec3 r = hinge_difference(position, hinge) + multipliers.hinge[j] / (k * h2);
        residual2 += glm::dot(r, r);
    }
    if (!topology.membranes.empty()) {
        const MembraneTensor c = membrane_tensor(springs);
        for (std::size_t j = 0; j < topology.membranes.size(); ++j) {
            const glm::dvec3 r = membrane_residual(position, topology.membranes[j], c, springs, h2, multipliers.membrane[j]);
            residual2 += glm::dot(r, r);
        }
    }
    const double first = multipliers.initial_violation;
    return first > 0.0 ? std::sqrt(residual2) / first : 0.0;
}

// The grid form (grid_xpbd.hpp) on a grid cloth with solver.method = "fast", the coloured form
// (coloured_xpbd.hpp) on any other cloth with it, the list order otherwise. Its residual is measured when asked
// (MassSpring::last_solver_residual), so the substep pays nothing for it.
void xpbd_substep(IntegratorContext& c) {
    IntegratorCaches& caches = c.caches;
    const bool fast = c.settings.solver.method == SolverMethod::Fast;
    if (fast && !caches.grid_xpbd_current) {
        caches.grid_xpbd = GridXpbd::for_topology(c.topology);
        if (caches.grid_xpbd) caches.grid_xpbd->set_stiffness(c.topology, c.settings.springs);
        caches.coloured_xpbd.reset();
        if (!caches.grid_xpbd) caches.coloured_xpbd = ColouredXpbd::for_topology(c.topology);
        if (caches.coloured_xpbd) caches.coloured_xpbd->set_stiffness(c.topology, c.settings.springs);
        caches.grid_xpbd_current = true;
    }
    caches.grid_xpbd_ran = fast && caches.grid_xpbd.has_value();
    caches.coloured_xpbd_ran = fast && !caches.grid_xpbd_ran && caches.coloured_xpbd.has_value();
    if (caches.grid_xpbd_ran) {
        caches.grid_xpbd->step(c.state, c.dynamics, c.h, c.settings.solver.threads);
    } else if (caches.coloured_xpbd_ran) {
        caches.coloured_xpbd->step(c.state, c.dynamics, c.topology, c.settings.springs, c.h, c.settings.solver.threads,
                                   caches.xpbd);
    } else {
        step_xpbd(c.state, c.dynamics, c.topology, c.settings.springs, c.h, caches.xpbd);
    }
    c.solve.iterations = 1;
}

}  // namespace clothsim
