// The readable view of one particle. The simulation itself stores particles as structure-of-arrays
// (clothsim::State); a Particle is assembled on request and never written back implicitly.
#pragma once

#include <glm/vec3.hpp>

namespace clothsim {

struct Particle {
    glm::vec3 position{0.0f};
    glm::vec3 previous_position{0.0f};  // one substep ago (position Verlet)
    float mass = 0.0f;                  // kg
    bool pinned = false;                // pinned particles never move
};

}  // namespace clothsim
