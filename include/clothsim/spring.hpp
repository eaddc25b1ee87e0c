// A Hooke spring between two particles: F = -k (|d| - L0) d/|d|, with k chosen by the spring's kind.
#pragma once

#include <cstdint>

namespace clothsim {

enum class SpringKind : std::uint8_t {
    Structural = 0,  // horizontal and vertical neighbours
    Shear = 1,       // both diagonals of a grid cell
    Bending = 2,     // two apart along rows and columns
};
inline constexpr int kSpringKindCount = 3;

const char* to_string(SpringKind kind);

// Topology only: which particles, how long at rest, which stiffness. Stiffness lives in SpringSettings so
// that changing it applies live, without rebuilding the spring list.
struct Spring {
    std::uint32_t a = 0;
    std::uint32_t b = 0;
    float rest_length = 0.0f;  // m
    SpringKind kind = SpringKind::Structural;
};

}  // namespace clothsim
