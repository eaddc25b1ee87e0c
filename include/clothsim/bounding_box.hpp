// An axis-aligned bounding box in float: the broad phase's boxes around particle blocks (broad_phase.hpp) and
// the colliders' reach (shapes/).
#pragma once

#include <glm/vec3.hpp>

#include <cmath>

namespace clothsim {

struct Box {
    glm::vec3 lo{INFINITY};
    glm::vec3 hi{-INFINITY};
    bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
};

}  // namespace clothsim
