// The textbook cloth step as most tutorials write it: an array of particle structs, one loop
// over a spring list, one over the particles. Benchmark-only: it is the baseline the performance targets
// were set against (../shared/PERFORMANCE_NOTES.md, "a textbook implementation ... 5.8 ns per spring-step").
// The same model as MassSpring (Hooke springs, gravity, damped position Verlet, ground); the tests compare
// the fast solver with the textbook SoA path inside MassSpring, and bench.cpp checks this one agrees too.
#pragma once

#include "clothsim/mass_spring.hpp"

#include <glm/geometric.hpp>

#include <vector>

namespace clothsim::bench {

class TextbookAos {
public:
    struct Particle {
        glm::vec3 position, previous, force;
        float inverse_mass;
        bool pinned;
    };

    explicit TextbookAos(const MassSpring& sim) : settings_(sim.settings()), springs_(sim.topology().springs) {
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            const Particle p{sim.position(i), sim.particle(i).previous_position, glm::vec3(0.0f),
                             sim.state().inverse_mass[i], sim.particle(i).pinned};
            particles_.push_back(p);
        }
    }

    void step() {
        const float h = settings_.integration.dt / static_cast<float>(settings_.integration.substeps);
        const float c = settings_.springs.damping;
        // The textbook baseline is an isotropic per-spring cloth: one k per kind (the u-axis value).
        const float k[3] = {settings_.springs.structural.x, settings_.springs.shear, settings_.springs.bending.x};
        for (Particle& p : particles_) p.force = glm::vec3(0.0f);
        for (const Spring& s : springs_) {
            Particle& a = particles_[s.a];
            Particle& b = particles_[s.b];
            const glm::vec3 d = b.position - a.position;
            const float length = glm::length(d);
            if (!(length > 1e-12f)) continue;
            const glm::vec3 f = (k[static_cast<int>(s.kind)] * (length - s.rest_length) / length) * d;
            a.force += f;
            b.force -= f;
        }
        const float keep = 1.0f - c * h / (1.0f + 0.5f * c * h), h2 = h * h / (1.0f + 0.5f * c * h);
        // The scene's first plane (the ground), the only collider this reference model knows.
        bool grounded = false;
        float floor = 0.0f;
        for (const Collider& collider : settings_.colliders.shapes) {
            if (const auto* plane = std::get_if<PlaneCollider>(&collider.shape); plane && collider.enabled && !grounded) {
                grounded = true;
                floor = plane->height + settings_.colliders.thickness;
            }
        }
        for (Particle& p : particles_) {
            if (p.pinned) continue;
            const glm::vec3 a = p.force * p.inverse_mass + settings_.forces.gravity;
            const glm::vec3 next = p.position + (p.position - p.previous) * keep + a * h2;
            p.previous = p.position;
            p.position = next;
            if (grounded && p.position.y < floor) p.position.y = floor;
        }
    }

    glm::vec3 position(std::size_t i) const { return particles_[i].position; }

private:
    SimulationSettings settings_;
    std::vector<Spring> springs_;
    std::vector<Particle> particles_;
};

}  // namespace clothsim::bench
