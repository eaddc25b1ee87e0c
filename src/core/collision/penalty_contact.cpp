#include "collision/penalty_contact.hpp"

#include "clothsim/collider.hpp"

#include <glm/geometric.hpp>

#include <algorithm>

namespace clothsim {
namespace {

// Calls visit(contact) for each enabled collider the particle at p touches (depth > 0), in the list's order.
template <class Visit>
void for_each_contact(const ColliderSettings& colliders, glm::dvec3 p, Visit visit) {
    const double t = colliders.thickness;
    for (const Collider& collider : colliders.shapes) {
        if (!collider.enabled) continue;
        const Contact<double> c = std::visit([&](const auto& shape) { return contact(shape, p, t); }, collider.shape);
        if (c.depth > 0.0) visit(c);
    }
}

}  // namespace

template <class F>
void accumulate_contact_forces(const State& state, const ColliderSettings& colliders, BasicVec3Array<F>& force) {
    const double t = colliders.thickness;
    if (!(t > 0.0)) return;
    const double scale = double(colliders.contact_stiffness) / (t * t);  // F = scale p^3
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) continue;
        glm::dvec3 f(0.0);
        bool touching = false;
        for_each_contact(colliders, state.position.get(i), [&](const Contact<double>& c) {
            f += (scale * c.depth * c.depth * c.depth) * c.normal;
            touching = true;
        });
        if (touching) force.add(i, glm::vec<3, F>(f));
    }
}

template void accumulate_contact_forces<float>(const State&, const ColliderSettings&, Vec3Array&);
template void accumulate_contact_forces<double>(const State&, const ColliderSettings&, DVec3Array&);

double contact_potential_energy(const State& state, const ColliderSettings& colliders) {
    const double t = colliders.thickness;
    if (!(t > 0.0)) return 0.0;
    const double scale = 0.25 * double(colliders.contact_stiffness) / (t * t);  // U = scale p^4
    double energy = 0.0;
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) continue;
        for_each_contact(colliders, state.position.get(i), [&](const Contact<double>& c) {
            const double p2 = c.depth * c.depth;
            energy += scale * p2 * p2;
        });
    }
    return energy;
}

double contact_stiffness_bound(const ColliderSettings& colliders) {
    const auto enabled = std::count_if(colliders.shapes.begin(), colliders.shapes.end(),
                                       [](const Collider& c) { return c.enabled; });
    return 3.0 * double(colliders.contact_stiffness) * double(enabled);
}

}  // namespace clothsim
