// The user's grab: a particle pulled toward the mouse's target by a critically damped spring whose force is
// capped, the way cloth follows the mouse in Blender or Ten Minute Physics: a fast drag leads the cloth
// instead of tearing it. MassSpring holds at most one (MassSpring::grab).
#pragma once

#include "clothsim/state.hpp"

#include <glm/vec3.hpp>

#include <cstddef>

namespace clothsim {

struct GrabSpring {
    std::size_t particle = 0;
    glm::vec3 target{0.0f};
    float force_limit = 0.0f;  // N
    // F = k (target - x) - c v with k = m / (4 h^2) and c = 2 sqrt(k m) (critical), |F| capped at force_limit;
    // v = motion / the state's substep (h before the first).
    glm::vec3 force(const State& state, double h) const;
};

}  // namespace clothsim
