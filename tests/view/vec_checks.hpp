// Checks on glm vectors that print both sides when they fail (shared by the camera and picking tests).
#pragma once

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <sstream>
#include <string>

namespace clothsim::test {

inline std::string str(glm::vec3 v) {
    std::ostringstream s;
    s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return s.str();
}

inline void check_near(glm::vec3 actual, glm::vec3 expected, float tolerance) {
    INFO("actual " << str(actual) << ", expected " << str(expected) << ", tolerance " << tolerance);
    CHECK(glm::length(actual - expected) <= tolerance);
}

}  // namespace clothsim::test
