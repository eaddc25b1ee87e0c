#include "integrators/verlet.hpp"

namespace clothsim {

void integrate_verlet(State& state, const Vec3Array& force, glm::vec3 gravity, double damping, double h) {
    integrate_verlet(state, force, gravity, damping, h, 0, state.size());
    state.substep = h;
}

void integrate_verlet(State& state, const Vec3Array& force, glm::vec3 gravity, double damping, double h,
                      std::size_t first, std::size_t last) {
    const auto [keep, h2] = verlet_coefficients(damping, h);
    DVec3Array& x = state.position;
    DVec3Array& motion = state.motion;
    for (std::size_t i = first; i < last; ++i) {
        if (state.pinned[i]) {
            motion.set(i, glm::dvec3(0.0));
            continue;
        }
        const glm::vec3 change = (force.get(i) * state.inverse_mass[i] + gravity) * h2;
        const glm::dvec3 step = motion.get(i) * keep + glm::dvec3(change);  // x' - x = (x - x_prev)(1 - d) + a h2
        motion.set(i, step);
        x.add(i, step);
    }
}

void start_verlet(State& state, const std::vector<glm::dvec3>& velocity, const Vec3Array& force,
                  glm::vec3 gravity, double damping, double h) {
    const glm::dvec3 g(gravity);
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) {
            state.motion.set(i, glm::dvec3(0.0));
            continue;
        }
        const glm::dvec3 v = velocity[i];
        const glm::dvec3 a = glm::dvec3(force.get(i)) * double(state.inverse_mass[i]) + g - damping * v;
        state.motion.set(i, v * h - a * (0.5 * h * h));
    }
    state.substep = h;
}

std::vector<glm::dvec3> verlet_velocities(const State& state, const Vec3Array& force, glm::vec3 gravity,
                                          double damping) {
    const double h = state.substep;
    std::vector<glm::dvec3> v(state.size(), glm::dvec3(0.0));
    if (!(h > 0.0)) return v;
    const double scale = 1.0 / (1.0 + 0.5 * damping * h);
    const glm::dvec3 g(gravity);
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) continue;
        const glm::dvec3 a = glm::dvec3(force.get(i)) * double(state.inverse_mass[i]) + g;
        v[i] = (state.motion.get(i) / h + a * (0.5 * h)) * scale;
    }
    return v;
}

}  // namespace clothsim
