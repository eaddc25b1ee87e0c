#include "integrators/integrators.hpp"
#include "integrators/integrator_step.hpp"

#include "model/forces.hpp"

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
    accelerations(state, wind, dynamics.gravity, dynamics.damping, a);
    const DVec3Array start = state.position;
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) continue;
        state.position.add(i, state.motion.get(i) + a.get(i) * (h * h));  // x + h (v + h a)
    }
    // One Gauss-Seidel pass over the springs; with lambda starting at 0 each substep,
    // d_lambda = -C / (w_a + w_b + alpha~), alpha~ = 1 / (k h^2), and x_a -= w_a lambda n, x_b += w_b lambda n with
    // n = d / |d|, computed as lambda / |d| times d. GridXpbd (grid_xpbd.hpp) does the same arithmetic in
    // another order.
    multipliers.spring.assign(topology.springs.size(), 0.0);
    multipliers.bend.assign(topology.bends.size(), glm::dvec3(0.0));
    multipliers.hinge.assign(topology.hinges.size(), glm::dvec3(0.0));
    double violation2 = 0.0;
    for (std::size_t j = 0; j < topology.springs.size(); ++j) {
        const Spring& s = topology.springs[j];
        const double k = stiffness_of(springs, s);
        if (k == 0.0) continue;
        const double wa = state.inverse_mass[s.a], wb = state.inverse_mass[s.b];
        const glm::dvec3 d = state.position.get(s.b) - state.position.get(s.a);
        const double length = std::sqrt((d.x * d.x + d.y * d.y) + d.z * d.z);
        if (!(length > 1e-12)) continue;
        const double c = length - static_cast<double>(s.rest_length);
        const double lambda = -c / ((wa + wb) + 1.0 / (k * h * h));
        multipliers.spring[j] = lambda;
        violation2 += c * c;
        const double g = lambda / length;
        state.position.add(s.a, d * -(wa * g));
        state.position.add(s.b, d * (wb * g));
    }
    // Bends: the vector constraint C = x_a - 2 x_m + x_b with compliance 1 / (k h^2) and gradients I, -2 I, I:
    // d_lambda = -C / (w_a + 4 w_m + w_b + 1 / (k h^2)).
    for (std::size_t j = 0; j < topology.bends.size(); ++j) {
        const Bend& b = topology.bends[j];
        const double k = stiffness_of(springs, b);
        if (k == 0.0) continue;
        const double wa = state.inverse_mass[b.a], wm = state.inverse_mass[b.m], wb = state.inverse_mass[b.b];
        const glm::dvec3 c = bend_difference(state.position, b);
        const glm::dvec3 lambda = c * (-1.0 / (((wa + 4.0 * wm) + wb) + 1.0 / (k * h * h)));
        multipliers.bend[j] = lambda;
        violation2 += (c.x * c.x + c.y * c.y) + c.z * c.z;
        state.position.add(b.a, wa * lambda);
        state.position.add(b.m, (-2.0 * wm) * lambda);
        state.position.add(b.b, wb * lambda);
    }
    // Hinges: the vector constraint C = sum_i c_i x_i with gradients c_i I:
    // d_lambda = -C / (sum_i w_i c_i^2 + 1 / (k h^2)).
    for (std::size_t j = 0; j < topology.hinges.size(); ++j) {
        const Hinge& hinge = topology.hinges[j];
        const double k = stiffness_of(springs, hinge);
        if (k == 0.0) continue;
        double w = 0.0;
        for (int i = 0; i < 4; ++i) w += double(state.inverse_mass[hinge.v[i]]) * double(hinge.c[i]) * double(hinge.c[i]);
        const glm::dvec3 c = hinge_difference(state.position, hinge);
        const glm::dvec3 lambda = c * (-1.0 / (w + 1.0 / (k * h * h)));
        multipliers.hinge[j] = lambda;
        violation2 += (c.x * c.x + c.y * c.y) + c.z * c.z;
        for (int i = 0; i < 4; ++i) {
            state.position.add(hinge.v[i], (double(state.inverse_mass[hinge.v[i]]) * double(hinge.c[i])) * lambda);
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
        multipliers.hinge.size() != topology.hinges.size()) {
        return 0.0;  // no XPBD substep yet
    }
    const double h2 = multipliers.substep * multipliers.substep;
    double residual2 = 0.0;
    for (std::size_t j = 0; j < topology.springs.size(); ++j) {
        const Spring& s = topology.springs[j];
        const double k = stiffness_of(springs, s);
        if (k == 0.0) continue;
        const double c = glm::length(position.get(s.b) - position.get(s.a)) - s.rest_length;
        const double r = c + multipliers.spring[j] / (k * h2);
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
    const double first = multipliers.initial_violation;
    return first > 0.0 ? std::sqrt(residual2) / first : 0.0;
}

// The grid form (grid_xpbd.hpp) on a grid cloth with solver.method = "fast", the list order otherwise. Its
// residual is measured when asked (MassSpring::last_solver_residual), so the substep pays nothing for it.
void xpbd_substep(IntegratorContext& c) {
    IntegratorCaches& caches = c.caches;
    const bool fast = c.settings.solver.method == SolverMethod::Fast;
    if (fast && !caches.grid_xpbd_current) {
        caches.grid_xpbd = GridXpbd::for_topology(c.topology);
        if (caches.grid_xpbd) caches.grid_xpbd->set_stiffness(c.topology, c.settings.springs);
        caches.grid_xpbd_current = true;
    }
    caches.grid_xpbd_ran = fast && caches.grid_xpbd.has_value();
    if (caches.grid_xpbd_ran) {
        caches.grid_xpbd->step(c.state, c.dynamics, c.h, c.settings.solver.threads);
    } else {
        step_xpbd(c.state, c.dynamics, c.topology, c.settings.springs, c.h, caches.xpbd);
    }
    c.solve.iterations = 1;
}

}  // namespace clothsim
