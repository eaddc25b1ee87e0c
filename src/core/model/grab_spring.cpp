#include "model/grab_spring.hpp"

#include <glm/geometric.hpp>

#include <cmath>

namespace clothsim {

glm::vec3 GrabSpring::force(const State& state, double h) const {
    const std::size_t i = particle;
    const double m = state.mass[i];
    const double k = 0.25 * m / (h * h);
    const double c = 2.0 * std::sqrt(k * m);
    const glm::dvec3 velocity = state.motion.get(i) / (state.substep > 0.0 ? state.substep : h);
    glm::dvec3 f = k * (glm::dvec3(target) - state.position.get(i)) - c * velocity;
    const double length = glm::length(f);
    if (!(length <= force_limit)) f *= length > 0.0 ? force_limit / length : 0.0;
    return glm::vec3(f);
}

}  // namespace clothsim
