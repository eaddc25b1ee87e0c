#include "model/forces.hpp"

#include "model/gaussian_curvature.hpp"
#include "model/membrane.hpp"

#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <numbers>

namespace clothsim {

template <class T>
void accumulate_spring_forces(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                              BasicVec3Array<T>& force) {
    using Vec = glm::vec<3, T>;
    for (const Spring& s : topology.springs) {
        const T ks = stiffness_of(springs, s);
        if (ks == T(0)) continue;
        const Vec d(position.get(s.b) - position.get(s.a));  // the difference in double, rounded once to T
        const T rest = s.rest_length;
        T scale;  // f_a = scale * d
        if (rest == T(0)) {
            scale = ks;
        } else {
            const T length = glm::length(d);
            if (!(length > T(1e-12f))) continue;
            scale = ks * curve_of(springs, s).stretch_term(length - rest, rest) / length;
        }
        const Vec f = scale * d;
        force.add(s.a, f);
        force.add(s.b, -f);
    }
    for (const Bend& b : topology.bends) {
        const T kb = stiffness_of(springs, b);
        if (kb == T(0)) continue;
        const Vec e = kb * Vec(bend_difference(position, b));  // the difference in double, rounded once to T
        force.add(b.a, -e);
        force.add(b.m, T(2) * e);
        force.add(b.b, -e);
    }
    for (const Hinge& h : topology.hinges) {
        const T kh = stiffness_of(springs, h);
        if (kh == T(0)) continue;
        const Vec e = kh * Vec(hinge_difference(position, h));
        for (int i = 0; i < 4; ++i) force.add(h.v[i], -T(h.c[i]) * e);
    }
    if (!topology.membranes.empty()) {
        const MembraneTensor c = membrane_tensor(springs);
        for (const Membrane& m : topology.membranes) {
            Vec pu, pv;
            if (!membrane_forces(position, m, c, springs, pu, pv)) continue;
            for (int i = 0; i < 3; ++i) {
                force.add(m.v[i], T(m.bu[i]) * pu);
                force.add(m.v[i], T(m.bv[i]) * pv);
            }
        }
    }
    accumulate_gaussian_forces(topology, position, springs, force);
}

glm::vec3 wind_velocity(const ForceSettings& forces, double time) {
    if (forces.gust_strength == 0.0f) return forces.wind;
    const double w = 2.0 * std::numbers::pi * forces.gust_frequency * time;
    const double gust = 0.6 * std::sin(w) + 0.4 * std::sin(2.718281828 * w + 1.3);
    return forces.wind * static_cast<float>(1.0 + forces.gust_strength * gust);
}

template <class F>
void accumulate_wind_forces(const Topology& topology, const State& state, const ForceSettings& forces,
                            double rest_area, BasicVec3Array<F>& force) {
    using T = double;
    using Vec = glm::dvec3;
    const Vec wind(wind_velocity(forces, state.time));
    const T drag = forces.drag;
    const T inv_h = state.substep > T(0) ? T(1) / state.substep : T(0);
    auto velocity = [&](std::size_t i) { return state.motion.get(i) * inv_h; };
    if (forces.wind_model == WindModel::Uniform) {
        const T area = rest_area / static_cast<T>(state.size());
        for (std::size_t i = 0; i < state.size(); ++i) {
            const Vec rel = wind - velocity(i);
            force.add(i, glm::vec<3, F>(drag * area * glm::length(rel) * rel));
        }
        return;
    }
    for (const auto& t : topology.triangles) {
        const Vec a = state.position.get(t[0]);
        const Vec cross = glm::cross(state.position.get(t[1]) - a, state.position.get(t[2]) - a);
        const T twice_area = glm::length(cross);
        if (!(twice_area > T(1e-12f))) continue;
        const Vec n = cross / twice_area;
        const Vec v = (velocity(t[0]) + velocity(t[1]) + velocity(t[2])) * (T(1) / T(3));
        const T wn = glm::dot(wind - v, n);
        const Vec f = (drag * T(0.5) * twice_area * wn * std::abs(wn) / T(3)) * n;
        const glm::vec<3, F> share(f);
        force.add(t[0], share);
        force.add(t[1], share);
        force.add(t[2], share);
    }
}

template <class F>
void accumulate_soft_clip_forces(const Topology& topology, const DVec3Array& position, BasicVec3Array<F>& force) {
    for (const SoftClipSpring& h : topology.clip_springs) {
        const glm::dvec3 f = -double(h.stiffness) * (position.get(h.particle) - h.anchor);
        force.add(h.particle, glm::vec<3, F>(f));
    }
}

template void accumulate_spring_forces<float>(const Topology&, const DVec3Array&, const SpringSettings&, Vec3Array&);
template void accumulate_spring_forces<double>(const Topology&, const DVec3Array&, const SpringSettings&,
                                               DVec3Array&);
template void accumulate_soft_clip_forces<float>(const Topology&, const DVec3Array&, Vec3Array&);
template void accumulate_soft_clip_forces<double>(const Topology&, const DVec3Array&, DVec3Array&);
template void accumulate_wind_forces<float>(const Topology&, const State&, const ForceSettings&, double, Vec3Array&);
template void accumulate_wind_forces<double>(const Topology&, const State&, const ForceSettings&, double,
                                             DVec3Array&);

double spring_potential_energy(const Topology& topology, const DVec3Array& position,
                               const SpringSettings& springs) {
    double energy = 0.0;
    for (const Spring& s : topology.springs) {
        const double k = stiffness_of(springs, s);
        const double stretch = glm::length(position.get(s.b) - position.get(s.a)) - s.rest_length;
        energy += spring_energy(k, curve_of(springs, s), stretch, s.rest_length);
    }
    for (const Bend& b : topology.bends) {
        const glm::dvec3 d = bend_difference(position, b);
        energy += 0.5 * double(stiffness_of(springs, b)) * glm::dot(d, d);
    }
    for (const Hinge& h : topology.hinges) {
        const glm::dvec3 d = hinge_difference(position, h);
        energy += 0.5 * double(stiffness_of(springs, h)) * glm::dot(d, d);
    }
    if (!topology.membranes.empty()) {
        const MembraneTensor c = membrane_tensor(springs);
        for (const Membrane& m : topology.membranes) energy += membrane_energy(position, m, c, springs);
    }
    energy += gaussian_energy(topology, position, springs);
    for (const SoftClipSpring& h : topology.clip_springs) {
        const glm::dvec3 d = position.get(h.particle) - h.anchor;
        energy += 0.5 * double(h.stiffness) * glm::dot(d, d);
    }
    return energy;
}

}  // namespace clothsim
