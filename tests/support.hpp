// Small scene builders shared by the physics tests.
#pragma once

#include "clothsim/scene.hpp"

#include <cstring>
#include <initializer_list>

namespace clothsim::test {

// Free particles of one mass at the given positions, at rest: every state array sized, nothing pinned.
inline State free_particles(std::initializer_list<glm::vec3> positions, float mass) {
    State st;
    st.position.resize(positions.size());
    st.motion.resize(positions.size());
    std::size_t i = 0;
    for (const glm::vec3& p : positions) st.position.set(i++, p);
    st.mass.assign(positions.size(), mass);
    st.inverse_mass.assign(positions.size(), 1.0f / mass);
    st.pinned.assign(positions.size(), 0);
    return st;
}

// A vertical chain of `particles` particles spaced `spacing` apart hanging down from the origin, with only
// structural springs of stiffness k, no gravity, no damping, no colliders, nothing pinned.
inline Scene chain(int particles, float spacing, float particle_mass, float k) {
    Scene s;
    s.cloth.rows = particles;
    s.cloth.cols = 1;
    s.cloth.size = {1.0f, particles > 1 ? spacing * static_cast<float>(particles - 1) : 1.0f};
    s.cloth.mass = particle_mass * static_cast<float>(particles);
    s.cloth.origin = {0.0f, 0.0f, 0.0f};
    s.pins.preset = PinPreset::None;
    s.settings.springs = {glm::vec2(k), 0.0f, glm::vec2(0.0f), 0.0f};
    s.settings.forces.gravity = {0.0f, 0.0f, 0.0f};
    s.settings.colliders.ground.enabled = false;
    s.settings.integration.substeps = 1;
    return s;
}

// Whether two simulations hold the same positions and motion, bit for bit.
inline bool bit_identical(const MassSpring& a, const MassSpring& b) {
    const State& sa = a.state();
    const State& sb = b.state();
    const std::size_t bytes = sa.size() * sizeof(sa.position.x[0]);
    return sa.size() == sb.size() && std::memcmp(sa.position.x.data(), sb.position.x.data(), bytes) == 0 &&
           std::memcmp(sa.position.y.data(), sb.position.y.data(), bytes) == 0 &&
           std::memcmp(sa.position.z.data(), sb.position.z.data(), bytes) == 0 &&
           std::memcmp(sa.motion.x.data(), sb.motion.x.data(), bytes) == 0 &&
           std::memcmp(sa.motion.y.data(), sb.motion.y.data(), bytes) == 0 &&
           std::memcmp(sa.motion.z.data(), sb.motion.z.data(), bytes) == 0;
}

// Changes `sim`'s live settings through its one call (MassSpring::apply), as the panel does.
template <class Edit>
void edit_settings(clothsim::MassSpring& sim, Edit edit) {
    clothsim::SimulationSettings settings = sim.settings();
    edit(settings);
    sim.apply(settings);
}

// A Cusick specimen: a 30 cm disc of n x n grid particles lying flat at y = 1, centred on the y axis,
// nothing pinned, ground off.
inline Scene disc_specimen(int n) {
    Scene s;
    s.cloth.rows = s.cloth.cols = n;
    s.cloth.size = {0.3f, 0.3f};
    s.cloth.origin = {-0.15f, 1.0f, -0.15f};
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.0f, 0.0f, 1.0f};
    s.cloth.shape = ClothShape::Disc;
    s.pins.preset = PinPreset::None;
    s.settings.colliders.ground.enabled = false;
    return s;
}

}  // namespace clothsim::test
