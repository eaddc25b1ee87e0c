#include "verlet.hpp"

namespace clothsim {

void integrate_verlet(State& state, const Vec3Array& force, glm::vec3 gravity, float damping, float h) {
    const auto [keep, h2] = verlet_coefficients(damping, h);
    const std::size_t n = state.size();
    Vec3Array& x = state.position;
    Vec3Array& motion = state.motion;
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) {
            motion.set(i, glm::vec3(0.0f));
            continue;
        }
        const glm::vec3 a = force.get(i) * state.inverse_mass[i] + gravity;
        const glm::vec3 step = motion.get(i) * keep + a * h2;  // x' - x = (x - x_prev)(1 - d) + a h^2/(1 + ch/2)
        motion.set(i, step);
        x.add(i, step);
    }
    state.substep = h;
}

void start_verlet(State& state, const std::vector<glm::vec3>& velocity, const Vec3Array& force,
                  glm::vec3 gravity, float damping, float h) {
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) {
            state.motion.set(i, glm::vec3(0.0f));
            continue;
        }
        const glm::vec3 v = velocity[i];
        const glm::vec3 a = force.get(i) * state.inverse_mass[i] + gravity - damping * v;
        state.motion.set(i, v * h - a * (0.5f * h * h));
    }
    state.substep = h;
}

std::vector<glm::vec3> verlet_velocities(const State& state, const Vec3Array& force, glm::vec3 gravity,
                                         float damping) {
    const float h = state.substep;
    std::vector<glm::vec3> v(state.size(), glm::vec3(0.0f));
    if (!(h > 0.0f)) return v;
    const float scale = 1.0f / (1.0f + 0.5f * damping * h);
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) continue;
        const glm::vec3 a = force.get(i) * state.inverse_mass[i] + gravity;
        v[i] = (state.motion.get(i) / h + a * (0.5f * h)) * scale;
    }
    return v;
}

}  // namespace clothsim
