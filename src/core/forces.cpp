#include "forces.hpp"

#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <numbers>

namespace clothsim {

void accumulate_spring_forces(const Topology& topology, const Vec3Array& position,
                              const SpringSettings& springs, Vec3Array& force) {
    const std::array<float, kSpringKindCount> k = {springs.structural, springs.shear, springs.bending};
    for (const Spring& s : topology.springs) {
        const float ks = k[static_cast<int>(s.kind)];
        if (ks == 0.0f) continue;
        const glm::vec3 d = position.get(s.b) - position.get(s.a);
        float scale;  // f_a = scale * d
        if (s.rest_length == 0.0f) {
            scale = ks;
        } else {
            const float length = glm::length(d);
            if (!(length > 1e-12f)) continue;
            scale = ks * (length - s.rest_length) / length;
        }
        const glm::vec3 f = scale * d;
        force.add(s.a, f);
        force.add(s.b, -f);
    }
}

glm::vec3 wind_velocity(const ForceSettings& forces, double time) {
    if (forces.gust_strength == 0.0f) return forces.wind;
    const double w = 2.0 * std::numbers::pi * forces.gust_frequency * time;
    const double gust = 0.6 * std::sin(w) + 0.4 * std::sin(2.718281828 * w + 1.3);
    return forces.wind * static_cast<float>(1.0 + forces.gust_strength * gust);
}

void accumulate_wind_forces(const Topology& topology, const State& state, const ForceSettings& forces,
                            float rest_area, Vec3Array& force) {
    const glm::vec3 wind = wind_velocity(forces, state.time);
    const float inv_h = state.substep > 0.0f ? 1.0f / state.substep : 0.0f;
    auto velocity = [&](std::size_t i) {
        return state.motion.get(i) * inv_h;
    };
    if (forces.wind_model == WindModel::Uniform) {
        const float area = rest_area / static_cast<float>(state.size());
        for (std::size_t i = 0; i < state.size(); ++i) {
            const glm::vec3 rel = wind - velocity(i);
            force.add(i, forces.drag * area * glm::length(rel) * rel);
        }
        return;
    }
    for (const auto& t : topology.triangles) {
        const glm::vec3 a = state.position.get(t[0]);
        const glm::vec3 cross = glm::cross(state.position.get(t[1]) - a, state.position.get(t[2]) - a);
        const float twice_area = glm::length(cross);
        if (!(twice_area > 1e-12f)) continue;
        const glm::vec3 n = cross / twice_area;
        const glm::vec3 v = (velocity(t[0]) + velocity(t[1]) + velocity(t[2])) * (1.0f / 3.0f);
        const float wn = glm::dot(wind - v, n);
        const glm::vec3 f = (forces.drag * 0.5f * twice_area * wn * std::fabs(wn) / 3.0f) * n;
        force.add(t[0], f);
        force.add(t[1], f);
        force.add(t[2], f);
    }
}

double spring_potential_energy(const Topology& topology, const Vec3Array& position,
                               const SpringSettings& springs) {
    double energy = 0.0;
    for (const Spring& s : topology.springs) {
        const double k = stiffness_of(springs, s.kind);
        const glm::vec3 d = position.get(s.b) - position.get(s.a);
        const double stretch = std::sqrt(double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z) - s.rest_length;
        energy += 0.5 * k * stretch * stretch;
    }
    return energy;
}

}  // namespace clothsim
