#include "clothsim/mass_spring.hpp"

#include "clothsim/colliders.hpp"
#include "forces.hpp"
#include "grid_solver.hpp"
#include "integrators.hpp"
#include "verlet.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace clothsim {

MassSpring::MassSpring(Topology topology, State state, SimulationSettings settings,
                       const std::vector<glm::vec3>& initial_velocity)
    : topology_(std::move(topology)), state_(std::move(state)), settings_(settings) {
    const std::size_t n = state_.size();
    if (state_.mass.size() != n || state_.inverse_mass.size() != n || state_.pinned.size() != n ||
        (!initial_velocity.empty() && initial_velocity.size() != n)) {
        throw std::invalid_argument("MassSpring: state arrays and initial velocities must have equal length");
    }
    for (const auto& t : topology_.triangles) {
        const glm::vec3 a = state_.position.get(t[0]);
        rest_area_ += 0.5f * glm::length(glm::cross(state_.position.get(t[1]) - a, state_.position.get(t[2]) - a));
    }
    force_.resize(n);
    state_.motion.resize(n);
    if (auto grid = GridSolver::for_topology(topology_)) grid_ = std::make_unique<GridSolver>(std::move(*grid));
    restart(initial_velocity.empty() ? std::vector<glm::vec3>(n, glm::vec3(0.0f)) : initial_velocity,
            substep_length());
}

MassSpring::~MassSpring() = default;
MassSpring::MassSpring(MassSpring&&) noexcept = default;
MassSpring& MassSpring::operator=(MassSpring&&) noexcept = default;
MassSpring::MassSpring(const MassSpring& other)
    : topology_(other.topology_),
      state_(other.state_),
      settings_(other.settings_),
      grid_(other.grid_ ? std::make_unique<GridSolver>(*other.grid_) : nullptr),
      force_(other.force_),
      rest_area_(other.rest_area_),
      carry_(other.carry_),
      last_iterations_(other.last_iterations_) {}
MassSpring& MassSpring::operator=(const MassSpring& other) {
    if (this != &other) *this = MassSpring(other);
    return *this;
}

const char* MassSpring::fast_kernel_name() { return GridSolver::kernel_name(); }

int MassSpring::solver_threads() const {
    const bool fast = grid_ && settings_.solver.method == SolverMethod::Fast &&
                      settings_.integration.integrator == Integrator::Verlet;
    return fast ? grid_->effective_threads(settings_.solver.threads) : 1;
}

float MassSpring::substep_length() const {
    return settings_.integration.dt / static_cast<float>(settings_.integration.substeps);
}

// The whole pipeline of one substep, in order: forces (springs, wind), integration (gravity and damping
// inside), collisions. The fast solver runs the same stages fused row by row (grid_solver.hpp says why).
void MassSpring::step() {
    const float h = substep_length();
    const Integrator integrator = settings_.integration.integrator;
    if (h != state_.substep || static_cast<int>(integrator) != state_.integrator) restart(velocities(), h);

    if (integrator != Integrator::Verlet) {
        step_velocity_integrator(integrator, h);
        collide_all(state_, settings_.colliders);
    } else if (grid_ && settings_.solver.method == SolverMethod::Fast) {
        const Vec3Array* external = nullptr;
        if (wind_active()) {
            force_.resize(state_.size());
            accumulate_wind_forces(topology_, state_, settings_.forces, rest_area_, force_);
            external = &force_;
        }
        grid_->step(state_, settings_, external, h, settings_.solver.threads);
    } else {
        compute_forces(state_, force_);
        integrate_verlet(state_, force_, settings_.forces.gravity, settings_.springs.damping, h);
        collide_all(state_, settings_.colliders);
    }
    if (settings_.springs.strain_limit > 0.0f || settings_.forces.max_speed > 0.0f) {
        limit_strain_and_speed(h);
        collide_all(state_, settings_.colliders);  // a correction must not leave a particle inside a collider
    }
    state_.time += h;
}

// Provot (1995): after the step, a spring longer than (1 + limit) L0 is shortened to that length, its ends
// moving in proportion to their inverse masses (one Gauss-Seidel pass, spring-list order). The correction
// adds no velocity of its own (like a collision push), and the ends' motion apart along the spring is
// removed, shared by inverse mass so momentum is kept: a spring held at its limit stops stretching instead
// of storing speed it cannot use. Then any particle moving faster than max_speed is slowed to it, its
// substep's displacement shortened with it. Both change the model where they act (docs/STABILITY.md).
void MassSpring::limit_strain_and_speed(float h) {
    const float limit = settings_.springs.strain_limit;
    if (limit > 0.0f) {
        for (const Spring& s : topology_.springs) {
            if (s.rest_length == 0.0f) continue;
            const float wa = state_.inverse_mass[s.a], wb = state_.inverse_mass[s.b];
            if (wa + wb == 0.0f) continue;
            const glm::vec3 d = state_.position.get(s.b) - state_.position.get(s.a);
            const float length = glm::length(d);
            const float longest = (1.0f + limit) * s.rest_length;
            if (!(length > longest)) continue;
            const glm::vec3 shorten = d * ((length - longest) / (length * (wa + wb)));
            state_.position.add(s.a, wa * shorten);
            state_.position.add(s.b, -wb * shorten);
            const glm::vec3 n = d / length;
            const float apart = glm::dot(state_.motion.get(s.b) - state_.motion.get(s.a), n);
            if (apart > 0.0f) {
                state_.motion.add(s.a, (wa / (wa + wb)) * apart * n);
                state_.motion.add(s.b, -(wb / (wa + wb)) * apart * n);
            }
        }
    }
    const float max_speed = settings_.forces.max_speed;
    if (max_speed > 0.0f) {
        const float longest_step = max_speed * h;
        for (std::size_t i = 0; i < state_.size(); ++i) {
            const glm::vec3 m = state_.motion.get(i);
            const float step = glm::length(m);
            if (!(step > longest_step)) continue;
            const glm::vec3 clamped = m * (longest_step / step);
            state_.position.add(i, clamped - m);  // the substep moved the particle by m: move it by clamped
            state_.motion.set(i, clamped);
        }
    }
}

// One file per integrator, one switch (as solver2d does): all share compute_forces and the collision stage.
void MassSpring::step_velocity_integrator(Integrator integrator, float h) {
    const ForceFunction forces = [this](const State& s, Vec3Array& f) { compute_forces(s, f); };
    const ForceFunction external = [this](const State& s, Vec3Array& f) {
        f.resize(s.size());
        if (wind_active()) accumulate_wind_forces(topology_, s, settings_.forces, rest_area_, f);
    };
    const Dynamics dynamics{forces, external, settings_.forces.gravity, settings_.springs.damping};
    switch (integrator) {
        case Integrator::SymplecticEuler: step_symplectic_euler(state_, dynamics, h); break;
        case Integrator::Rk4: step_rk4(state_, dynamics, h); break;
        case Integrator::ImplicitEuler:
            last_iterations_ = step_implicit_euler(state_, dynamics, topology_, settings_.springs,
                                                   settings_.integration.tolerance, h);
            break;
        case Integrator::Xpbd: step_xpbd(state_, dynamics, topology_, settings_.springs, h); break;
        case Integrator::Verlet: break;  // handled by step()
    }
}

bool MassSpring::wind_active() const {
    return settings_.forces.wind != glm::vec3(0.0f) || settings_.forces.wind_model == WindModel::Uniform;
}

void MassSpring::compute_forces(const State& state, Vec3Array& force) const {
    force.resize(state.size());
    accumulate_spring_forces(topology_, state.position, settings_.springs, force);
    if (wind_active()) {
        // Wind is summed on its own and added last, as the fast solver adds it, so both round alike.
        Vec3Array wind;
        wind.resize(state.size());
        accumulate_wind_forces(topology_, state, settings_.forces, rest_area_, wind);
        for (std::size_t i = 0; i < state.size(); ++i) force.add(i, wind.get(i));
    }
}

void MassSpring::run_steps(long long steps) {
    for (long long s = 0; s < steps; ++s) {
        for (int i = 0; i < settings_.integration.substeps; ++i) step();
    }
}

long long MassSpring::advance(double seconds) {
    carry_ += seconds;
    const double h = substep_length();
    // The small tolerance keeps 1/60 s from becoming 9.9999 substeps of 1/600 s through rounding.
    const auto n = static_cast<long long>(std::floor(carry_ / h + 1e-6));
    for (long long i = 0; i < n; ++i) step();
    carry_ = std::max(0.0, carry_ - static_cast<double>(n) * h);
    return n;
}

void MassSpring::restart(const std::vector<glm::vec3>& velocity, float h) {
    const Integrator integrator = settings_.integration.integrator;
    state_.integrator = static_cast<int>(integrator);
    if (integrator == Integrator::Verlet) {
        compute_forces(state_, force_);
        start_verlet(state_, velocity, force_, settings_.forces.gravity, settings_.springs.damping, h);
        return;
    }
    // The velocity integrators keep motion = v h.
    for (std::size_t i = 0; i < state_.size(); ++i) {
        state_.motion.set(i, state_.pinned[i] ? glm::vec3(0.0f) : velocity[i] * h);
    }
    state_.substep = h;
}

Particle MassSpring::particle(std::size_t i) const {
    const glm::vec3 x = state_.position.get(i);
    return {x, x - state_.motion.get(i), state_.mass[i], state_.pinned[i] != 0};
}

std::vector<glm::vec3> MassSpring::positions() const {
    std::vector<glm::vec3> p(state_.size());
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = state_.position.get(i);
    return p;
}

std::vector<glm::vec3> MassSpring::velocities() const {
    if (state_.integrator != static_cast<int>(Integrator::Verlet)) {
        std::vector<glm::vec3> v(state_.size(), glm::vec3(0.0f));
        if (state_.substep > 0.0f) {
            for (std::size_t i = 0; i < v.size(); ++i) v[i] = state_.motion.get(i) / state_.substep;
        }
        return v;
    }
    Vec3Array force;
    compute_forces(state_, force);
    return verlet_velocities(state_, force, settings_.forces.gravity, settings_.springs.damping);
}

Energy MassSpring::energy() const {
    Energy e;
    const std::vector<glm::vec3> v = velocities();
    const glm::dvec3 g(settings_.forces.gravity);
    for (std::size_t i = 0; i < state_.size(); ++i) {
        if (state_.pinned[i]) continue;
        const double m = state_.mass[i];
        e.kinetic += 0.5 * m * glm::dot(glm::dvec3(v[i]), glm::dvec3(v[i]));
        e.gravity_potential -= m * glm::dot(g, glm::dvec3(state_.position.get(i)));
    }
    e.spring_potential = spring_potential_energy(topology_, state_.position, settings_.springs);
    return e;
}

glm::vec3 MassSpring::momentum() const {
    const std::vector<glm::vec3> v = velocities();
    glm::dvec3 p(0.0);
    for (std::size_t i = 0; i < state_.size(); ++i) {
        if (!state_.pinned[i]) p += double(state_.mass[i]) * glm::dvec3(v[i]);
    }
    return glm::vec3(p);
}

bool MassSpring::all_finite() const {
    for (std::size_t i = 0; i < state_.size(); ++i) {
        if (!std::isfinite(state_.position.x[i]) || !std::isfinite(state_.position.y[i]) ||
            !std::isfinite(state_.position.z[i])) {
            return false;
        }
    }
    return true;
}

void MassSpring::set_pinned(std::size_t i, bool pinned) {
    state_.pinned.at(i) = pinned ? 1 : 0;
    state_.inverse_mass[i] = pinned ? 0.0f : 1.0f / state_.mass[i];
    if (pinned) state_.motion.set(i, glm::vec3(0.0f));
}

void MassSpring::move_pinned(std::size_t i, glm::vec3 position) {
    if (!state_.pinned.at(i)) return;
    state_.position.set(i, position);
    state_.motion.set(i, glm::vec3(0.0f));
}

void MassSpring::set_particle(std::size_t i, glm::vec3 position, glm::vec3 velocity) {
    std::vector<glm::vec3> v = velocities();
    state_.position.set(i, position);
    v.at(i) = state_.pinned[i] ? glm::vec3(0.0f) : velocity;
    restart(v, substep_length());
}

void scene_bounds(const MassSpring& sim, glm::vec3& lo, glm::vec3& hi) {
    lo = glm::vec3(INFINITY);
    hi = glm::vec3(-INFINITY);
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        const glm::vec3 p = sim.position(i);
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const ColliderSettings& c = sim.settings().colliders;
    if (c.sphere.enabled) {
        lo = glm::min(lo, c.sphere.center - glm::vec3(c.sphere.radius));
        hi = glm::max(hi, c.sphere.center + glm::vec3(c.sphere.radius));
    }
    if (c.cube.enabled) {
        lo = glm::min(lo, c.cube.center - 0.5f * c.cube.size);
        hi = glm::max(hi, c.cube.center + 0.5f * c.cube.size);
    }
    if (!(lo.x <= hi.x)) lo = hi = glm::vec3(0.0f);
    if (c.ground.enabled) {
        lo.y = std::min(lo.y, c.ground.height);
        hi.y = std::max(hi.y, c.ground.height);
    }
}

}  // namespace clothsim
