#include "clothsim/strain.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace clothsim {
namespace {

double max_strain_of(const Topology& topology, const DVec3Array& position,
                     const std::array<bool, kSpringKindCount>& counted) {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    double largest = -std::numeric_limits<double>::infinity();
    bool any = false;
    for (const Spring& s : topology.springs) {
        if (!counted[static_cast<int>(s.kind)] || !(s.rest_length > 0.0f)) continue;
        const double strain = glm::length(position.get(s.b) - position.get(s.a)) / s.rest_length - 1.0;
        if (!std::isfinite(strain)) return nan;  // a cloth that blew up has no meaningful largest strain
        largest = std::max(largest, strain);
        any = true;
    }
    return any ? largest : nan;
}

}  // namespace

double max_strain(const Topology& topology, const DVec3Array& position, SpringKind kind) {
    std::array<bool, kSpringKindCount> counted{};
    counted[static_cast<int>(kind)] = true;
    return max_strain_of(topology, position, counted);
}

double max_membrane_strain(const Topology& topology, const DVec3Array& position) {
    std::array<bool, kSpringKindCount> counted{};
    counted[static_cast<int>(SpringKind::Structural)] = true;
    counted[static_cast<int>(SpringKind::Shear)] = true;
    return max_strain_of(topology, position, counted);
}

}  // namespace clothsim
