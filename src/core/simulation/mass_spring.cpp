#include "clothsim/mass_spring.hpp"

#include "clothsim/colliders.hpp"
#include "clothsim/tearing.hpp"
#include "clothsim/tethers.hpp"
#include "model/forces.hpp"
#include "integrators/fast_solver.hpp"
#include "integrators/grid_xpbd.hpp"
#include "integrators/integrator_step.hpp"
#include "integrators/integrators.hpp"
#include "collision/penalty_contact.hpp"
#include "integrators/projective.hpp"
#include "integrators/verlet.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {

// Stamps are unique across all simulations, so a copy keeps its stamp and a new cloth never reuses one.
std::uint64_t next_stamp() {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
}

}  // namespace

MassSpring::FastSolverHolder::FastSolverHolder() = default;
MassSpring::FastSolverHolder::FastSolverHolder(std::unique_ptr<FastSolver> s) : solver(std::move(s)) {}
MassSpring::FastSolverHolder::FastSolverHolder(const FastSolverHolder& other)
    : solver(other.solver ? std::make_unique<FastSolver>(*other.solver) : nullptr) {}
MassSpring::FastSolverHolder& MassSpring::FastSolverHolder::operator=(const FastSolverHolder& other) {
    if (this != &other) solver = other.solver ? std::make_unique<FastSolver>(*other.solver) : nullptr;
    return *this;
}
MassSpring::FastSolverHolder::FastSolverHolder(FastSolverHolder&&) noexcept = default;
MassSpring::FastSolverHolder& MassSpring::FastSolverHolder::operator=(FastSolverHolder&&) noexcept = default;
MassSpring::FastSolverHolder::~FastSolverHolder() = default;

MassSpring::MassSpring(Topology topology, State state, SimulationSettings settings,
                       const std::vector<glm::vec3>& initial_velocity)
    : topology_(std::move(topology)), state_(std::move(state)), settings_(settings) {
    const std::size_t n = state_.size();
    if (state_.mass.size() != n || state_.inverse_mass.size() != n || state_.pinned.size() != n ||
        (!initial_velocity.empty() && initial_velocity.size() != n)) {
        throw std::invalid_argument("MassSpring: state arrays and initial velocities must have equal length");
    }
    // The plan reads the counts; a hand-made topology may not have filled them in.
    topology_.count_by_kind();
    for (const auto& t : topology_.triangles) {
        const glm::dvec3 a = state_.position.get(t[0]);
        rest_area_ += static_cast<float>(
            0.5 * glm::length(glm::cross(state_.position.get(t[1]) - a, state_.position.get(t[2]) - a)));
    }
    force_.resize(n);
    state_.motion.resize(n);
    build_fast_solver();
    blocks_.start = block_starts(n, topology_.rows, topology_.cols);
    rest_position_ = state_.position;  // the builder makes the cloth flat, at rest
    spacing_ = particle_spacing(topology_);
    tethers_ = build_tethers(topology_, state_, rest_position_);
    whole_cells_ = whole_cells(topology_, n);
    surface_ = build_cloth_surface(topology_, rest_position_, whole_cells_);
    replan();
    restart(initial_velocity.empty() ? std::vector<glm::dvec3>(n, glm::dvec3(0.0))
                                     : std::vector<glm::dvec3>(initial_velocity.begin(), initial_velocity.end()),
            substep_length());
    stamp_ = next_stamp();
    setup_stamp_ = next_stamp();
    topology_stamp_ = next_stamp();
}

struct MassSpring::IterativeSolvers::Data : IntegratorCaches {};
MassSpring::IterativeSolvers::IterativeSolvers() : data(std::make_unique<Data>()) {}
MassSpring::IterativeSolvers::IterativeSolvers(const IterativeSolvers& other)
    : data(std::make_unique<Data>(*other.data)) {}
MassSpring::IterativeSolvers& MassSpring::IterativeSolvers::operator=(const IterativeSolvers& other) {
    if (this != &other) data = std::make_unique<Data>(*other.data);
    return *this;
}
MassSpring::IterativeSolvers::IterativeSolvers(IterativeSolvers&&) noexcept = default;
MassSpring::IterativeSolvers& MassSpring::IterativeSolvers::operator=(IterativeSolvers&&) noexcept = default;
MassSpring::IterativeSolvers::~IterativeSolvers() = default;
void MassSpring::IterativeSolvers::invalidate() {
    if (!data) return;
    data->projective.invalidate_matrix();
    data->grid_xpbd_current = false;
}

MassSpring::~MassSpring() = default;
MassSpring::MassSpring(const MassSpring&) = default;
MassSpring& MassSpring::operator=(const MassSpring&) = default;
MassSpring::MassSpring(MassSpring&&) noexcept = default;
MassSpring& MassSpring::operator=(MassSpring&&) noexcept = default;

const char* MassSpring::fast_kernel_name() { return FastSolver::kernel_name(); }

bool MassSpring::use_fast_kernel(const std::string& name) {
    for (FastKernel k : {FastKernel::Generic, FastKernel::Avx2, FastKernel::Avx512}) {
        const bool named = name == FastSolver::kernel_name(k) || (k == FastKernel::Avx2 && name == "avx2");
        if (!named) continue;
        if (static_cast<int>(k) > static_cast<int>(FastSolver::best_kernel())) return false;
        FastSolver::use_kernel(k);
        return true;
    }
    return false;
}

int MassSpring::solver_threads() const {
    if (plan_.path != StepPath::FastVerlet) {
        const bool grid = last_step_fast() && iterative_.data->grid_xpbd;
        return grid ? iterative_.data->grid_xpbd->effective_threads(settings_.solver.threads) : 1;
    }
    const bool set_aside = settings_.solver.threads == 0 && fast_.solver->team_set_aside();
    return set_aside ? 1 : fast_.solver->effective_threads(settings_.solver.threads);
}

bool MassSpring::last_step_fast() const {
    if (plan_.path == StepPath::FastVerlet) return true;
    return settings_.integration.integrator == Integrator::Xpbd && state_.integrator == Integrator::Xpbd &&
           iterative_.data->grid_xpbd_ran;
}

double MassSpring::substep_length() const {
    return static_cast<double>(settings_.integration.dt) / settings_.integration.substeps;
}

void MassSpring::apply(const SimulationSettings& settings) {
    if (settings == settings_) return;
    // The projective solver's matrix holds the stiffness, the substep and the damping.
    if (settings.springs != settings_.springs || settings.integration != settings_.integration) {
        iterative_.invalidate();
    }
    // Soft clips hold in proportion to the sheet's stiffness.
    if (settings.springs.structural != settings_.springs.structural) {
        for (Hold& hold : topology_.holds) {
            if (hold.share_u > 0.0f || hold.share_v > 0.0f) hold.stiffness = hold.stiffness_for(settings.springs.structural);
        }
    }
    settings_ = settings;
    if (grab_) grab_->force_limit = grab_force_limit(grab_->particle);  // it follows the springs' k
    replan();
    wake();  // a changed setting (a collider moved, wind, a slider) is something driving the cloth
    // Self-collision's list and budget say nothing of what the cloth did while the stage was off or set
    // otherwise: it tests afresh at its next substep.
    if (self_collision_) self_collision_->invalidate();
    setup_stamp_ = next_stamp();
}

void MassSpring::set_substeps(int substeps) {
    SimulationSettings s = settings_;
    s.integration.substeps = substeps;
    apply(s);
}

// The whole pipeline of one substep, in order. The stages come from the plan (step_plan.hpp), made when the
// settings were applied; a stage the plan leaves out is not run, not even as a branch per particle.
void MassSpring::substep() {
    const double h = substep_length();
    if (sleep_.asleep()) {
        state_.time += h;
        ++profile_.slept_substeps;
        return;
    }
    StepProfile* profile = profiling_ ? &profile_ : nullptr;
    blocks_.positions_moving();
    const Integrator integrator = settings_.integration.integrator;
    if (h != state_.substep || integrator != state_.integrator) restart(velocities_in_double(), h);
    const bool continues = stamp_ == history_stamp_;  // nothing but the last step moved the cloth since
    if (!continues) blocks_.moved_outside_motion();    // an edit may have moved particles
    // A dragged pin moves outside the motions the broad phase and self-collision count.
    if (!pin_targets_.empty() && move_dragged_pins()) {
        blocks_.moved_outside_motion();
        if (self_collision_) self_collision_->invalidate();
    }
    // Self-collision's list of near pairs holds while only steps move the particles (self_collision.hpp).
    if (!continues && self_collision_) self_collision_->invalidate();

    switch (plan_.path) {
        case StepPath::FastVerlet: step_fast(h, profile); break;
        case StepPath::TextbookVerlet: step_textbook(h, profile); break;
        case StepPath::VelocityIntegrator: {
            StageTimer timer(profile, Stage::Integrate);
            step_velocity_integrator(integrator, h, continues);
        } break;
    }
    // The fast solver's sweep may have taken the bounds of the motion it wrote; they hold until a stage moves a
    // particle.
    const bool swept_bounds = plan_.path == StepPath::FastVerlet && sweep_takes_motion_bounds();
    const bool collided = collide(profile, swept_bounds ? &motion_bounds_ : nullptr);
    const MotionBounds* known = swept_bounds && !collided ? &motion_bounds_ : nullptr;
    // Moves outside the motions, which self-collision's budget does not count: a collider's push now, what
    // the stages after the last substep's self stage did, and the steps of RK4 and projective, whose motion
    // (v h at the substep's end) is not the substep's displacement.
    const bool displaced = !integrator_info(integrator).motion_is_displacement;
    const bool self_moved =
        plan_.self_collision && collide_self(profile, known, collided || moved_uncounted_ || displaced);
    moved_uncounted_ = false;
    if (self_moved || plan_.tethers || plan_.strain_limit || plan_.speed_limit) {
        if (plan_.tethers) {
            StageTimer timer(profile, Stage::Tethers);
            tethers_at_limit_ = apply_tethers();
        }
        bool limited = false;
        if (plan_.strain_limit) {
            StageTimer timer(profile, Stage::StrainLimit);
            limited = limit_strain();
        }
        if (plan_.speed_limit) {
            StageTimer timer(profile, Stage::SpeedLimit);
            limited = limit_speed(h) || limited;
        }
        if (self_moved || limited) blocks_.moved_outside_motion();  // pushes and limits; tethers stay inside it
        if (plan_.tethers && tethers_at_limit_ > 0 && blocks_.carried_valid) {
            // A tether keeps its particle in the carried box but takes the outward part of its motion, which
            // moves the start of its path (x - motion, where the swept tests begin) by at most that motion.
            blocks_.widen_carried(swept_bounds && !collided ? motion_bounds_.largest() : NAN);
        }
        blocks_.positions_moving();
        blocks_.boxes_current = box_blocks_on_team(profile);
        const bool pushed = collide(profile);  // a push or a correction must not leave a particle inside a collider
        moved_uncounted_ = pushed || limited || (plan_.tethers && tethers_at_limit_ > 0);
    }
    state_.time += h;
    ++profile_.substeps;
    stamp_ = next_stamp();
    history_stamp_ = stamp_;
    if (++substeps_since_check_ >= settings_.integration.substeps) {
        substeps_since_check_ = 0;
        if (plan_.tear) {
            StageTimer timer(profile, Stage::Tear);
            tear();
        }
        if (plan_.may_sleep) {
            StageTimer timer(profile, Stage::Sleep);
            sleep_.check(state_, settings_.solver, h, !pin_targets_.empty());  // a pin on its way drives the cloth
        }
    }
}

// Fast solver: wind, penalty contact and soft clips first (they read the positions before the fast solver
// moves them), then one fused sweep over the rows that also leaves each row's box for the collision broad phase.
void MassSpring::step_fast(double h, StepProfile* profile) {
    const Vec3Array* external = nullptr;
    if (plan_.wind || plan_.contact) {
        force_.resize(state_.size());
        add_external_forces(state_, force_, external_, profile);  // onto zeros: the sums themselves
        if (grab_) force_.add(grab_->particle, grab_force(state_));
        external = &force_;
    } else if (grab_ || plan_.holds) {
        // Forces on a few particles: written into an array that stays zero elsewhere, instead of summing a
        // whole array every substep (soft clips hold tens of particles of thousands).
        if (grab_external_.size() != state_.size()) grab_external_.resize(state_.size());
        if (grab_) grab_external_.set(grab_->particle, glm::vec3(0.0f));
        if (plan_.holds) {
            StageTimer timer(profile, Stage::Clips);
            for (const Hold& hold : topology_.holds) grab_external_.set(hold.particle, glm::vec3(0.0f));
            accumulate_hold_forces(topology_, state_.position, grab_external_);
        }
        if (grab_) grab_external_.add(grab_->particle, grab_force(state_));
        external = &grab_external_;
    }
    const bool boxes = plan_.colliders && settings_.solver.broad_phase;
    if (boxes) blocks_.bounds = block_bounds_for(settings_.colliders, blocks_);
    {
        StageTimer timer(profile, Stage::Fast);
        fast_.solver->step(state_, settings_, plan_.spring_mask(), external, h, boxes ? &blocks_.boxes : nullptr,
                           sweep_takes_motion_bounds() ? &motion_bounds_ : nullptr, blocks_.bounds);
    }
    blocks_.boxes_current = boxes;
    blocks_.current = false;  // the cloth's box is the union, made by the collision stage
}

void MassSpring::step_textbook(double h, StepProfile* profile) {
    force_.resize(state_.size());
    if (plan_.any_springs()) {
        StageTimer timer(profile, Stage::Springs);
        accumulate_spring_forces(topology_, state_.position, settings_.springs, force_);
    }
    if (plan_.external_forces()) add_external_forces(state_, force_, external_, profile);
    if (grab_) force_.add(grab_->particle, grab_force(state_));
    {
        StageTimer timer(profile, Stage::Integrate);
        integrate_verlet(state_, force_, settings_.forces.gravity, settings_.springs.damping, h);
    }
}

// On the fast path the tethers run on the fast solver's threads, each on the row block it has just swept, whose
// particles are in that core's caches (one thread over the whole cloth would move the other core's block to
// it and back every substep). Particles project independently (tethers.hpp), so the result is the same on any
// number of threads.
std::size_t MassSpring::apply_tethers() {
    const double strain = settings_.springs.tether_strain;
    if (plan_.path != StepPath::FastVerlet || !fast_.solver) return project_tethers(state_, tethers_, strain);
    std::array<std::size_t, 64> active{};
    const auto cols = static_cast<std::uint32_t>(topology_.cols);
    fast_.solver->for_each_block([&](int block, int begin, int end) {
        const std::size_t first = first_tether_from(tethers_, static_cast<std::uint32_t>(begin) * cols);
        const std::size_t last = first_tether_from(tethers_, static_cast<std::uint32_t>(end) * cols);
        active[static_cast<std::size_t>(block)] = project_tethers(state_, tethers_, strain, first, last);
    });
    std::size_t total = 0;
    for (std::size_t a : active) total += a;
    return total;
}

// The same split for the boxes of the collision broad phase's blocks (block_starts' grid layout, row by
// row), which the collision stage would otherwise make again block by block on one thread.
bool MassSpring::box_blocks_on_team(StepProfile* profile) {
    if (plan_.path != StepPath::FastVerlet || !fast_.solver || !plan_.colliders || !settings_.solver.broad_phase) {
        return false;
    }
    StageTimer timer(profile, Stage::BroadPhase);
    const int cols = topology_.cols;
    const std::size_t per_row = blocks_per_row(cols);
    const BlockBounds bounds = block_bounds_for(settings_.colliders, blocks_);
    blocks_.bounds = bounds;
    blocks_.boxes.resize(static_cast<std::size_t>(topology_.rows) * per_row);
    fast_.solver->for_each_block([&](int, int begin, int end) {
        for (int r = begin; r < end; ++r) {
            row_block_bounds(state_.position, static_cast<std::size_t>(r) * cols, static_cast<std::size_t>(cols),
                             blocks_.boxes.data() + static_cast<std::size_t>(r) * per_row, bounds);
        }
    });
    return true;
}

bool MassSpring::sweep_takes_motion_bounds() const {
    const bool swept_boxes = settings_.solver.broad_phase && plan_.solids;
    return plan_.self_collision || swept_boxes;
}

bool MassSpring::collide(StepProfile* profile, const MotionBounds* motion) {
    if (!plan_.colliders) {
        blocks_.moved_outside_motion();  // not grown while no stage reads it
        return false;
    }
    return collide_stage(state_, settings_.colliders, settings_.solver.broad_phase, blocks_, profile, solver_threads(),
                         motion);
}

// The cloth against itself (self_collision.hpp), built the first time it runs.
bool MassSpring::collide_self(StepProfile* profile, const MotionBounds* known, bool uncounted) {
    StageTimer timer(profile, Stage::SelfCollision);
    if (!self_collision_) self_collision_.emplace(topology_, rest_position_);
    const SelfCollisionCounts counts = self_collision_->collide(state_, settings_.collision, rest_position_, known, uncounted);
    if (profile) {
        profile->self_tiles += counts.tiles;
        profile->self_tiles_active += counts.tiles_active;
        profile->self_contacts += counts.contacts;
    }
    return counts.contacts > 0 || counts.clamped > 0;
}

// Springs beyond tear_strain break (tearing.hpp). The rest follows the new topology at the point of change:
// the fast solver's layout, the projective matrix, the tethers (a piece torn off is no longer held by the
// pins it hung from), the plan, and the stamps the renderer and the stability limit watch.
void MassSpring::tear() {
    topology_changed(tear_springs(topology_, state_.position, settings_.springs.tear_strain));
}

std::size_t MassSpring::cut(const std::function<bool(glm::vec3, glm::vec3)>& crosses) {
    const std::size_t removed =
        break_springs(topology_, [&](const Spring& s) { return crosses(position(s.a), position(s.b)); });
    topology_changed(removed);
    if (removed > 0) wake();
    return removed;
}

void MassSpring::topology_changed(std::size_t removed) {
    if (removed == 0) return;
    broken_springs_ += removed;
    build_fast_solver();
    iterative_.invalidate();
    if (self_collision_) self_collision_->update_neighbours(topology_, rest_position_);
    rebuild_tethers();
    surface_ = build_cloth_surface(topology_, rest_position_, whole_cells_);
    replan();
    setup_stamp_ = next_stamp();
    topology_stamp_ = next_stamp();
}

// The fast solver's layout of the current topology, or none when it is no grid.
void MassSpring::build_fast_solver() {
    fast_ = FastSolverHolder{};
    if (auto solver = FastSolver::for_topology(topology_)) {
        fast_ = FastSolverHolder(std::make_unique<FastSolver>(std::move(*solver)));
    }
}

// Tethers to the current pins; after a tear only within each piece (a piece torn off falls freely).
void MassSpring::rebuild_tethers() {
    tethers_ = build_tethers(topology_, state_, rest_position_);
    tethers_at_limit_ = 0;
    if (broken_springs_ == 0 || tethers_.empty()) return;
    const std::vector<std::uint32_t> piece = connected_pieces(topology_, state_.size());
    Tethers kept;
    for (std::size_t t = 0; t < tethers_.size(); ++t) {
        if (piece[tethers_.particle[t]] != piece[tethers_.anchor[t]]) continue;
        kept.particle.push_back(tethers_.particle[t]);
        kept.anchor.push_back(tethers_.anchor[t]);
        kept.rest.push_back(tethers_.rest[t]);
    }
    tethers_ = std::move(kept);
}

void MassSpring::replan() {
    plan_ = plan_step(topology_, settings_, fast_.solver != nullptr, !tethers_.empty());
}

void MassSpring::wake() {
    substeps_since_check_ = 0;
    if (sleep_.wake()) restart(std::vector<glm::dvec3>(state_.size(), glm::dvec3(0.0)), substep_length());
}

// Provot (1995): after the step, a spring longer than (1 + limit) L0 is shortened to that length, its ends
// moving in proportion to their inverse masses (one Gauss-Seidel pass, spring-list order). The correction
// adds no velocity of its own (like a collision push), and the ends' motion apart along the spring is
// removed, shared by inverse mass so momentum is kept: a spring held at its limit stops stretching instead
// of storing speed it cannot use. It changes the model where it acts (docs/STABILITY.md).
bool MassSpring::limit_strain() {
    const double limit = settings_.springs.strain_limit;
    bool changed = false;
    for (const Spring& s : topology_.springs) {
        if (s.rest_length == 0.0f) continue;
        const double wa = state_.inverse_mass[s.a], wb = state_.inverse_mass[s.b];
        if (wa + wb == 0.0) continue;
        const glm::dvec3 d = state_.position.get(s.b) - state_.position.get(s.a);
        const double length = glm::length(d);
        const double longest = (1.0 + limit) * s.rest_length;
        if (!(length > longest)) continue;
        const glm::dvec3 shorten = d * ((length - longest) / (length * (wa + wb)));
        changed = true;
        state_.position.add(s.a, wa * shorten);
        state_.position.add(s.b, -wb * shorten);
        const glm::dvec3 n = d / length;
        const double apart = glm::dot(state_.motion.get(s.b) - state_.motion.get(s.a), n);
        if (apart > 0.0) {
            state_.motion.add(s.a, (wa / (wa + wb)) * apart * n);
            state_.motion.add(s.b, -(wb / (wa + wb)) * apart * n);
        }
    }
    return changed;
}

// Any particle moving faster than max_speed is slowed to it, its substep's displacement shortened with it.
bool MassSpring::limit_speed(double h) {
    const double longest_step = settings_.forces.max_speed * h;
    bool changed = false;
    for (std::size_t i = 0; i < state_.size(); ++i) {
        const glm::dvec3 m = state_.motion.get(i);
        const double step = glm::length(m);
        if (!(step > longest_step)) continue;
        const glm::dvec3 clamped = m * (longest_step / step);
        state_.position.add(i, clamped - m);  // the substep moved the particle by m: move it by clamped
        state_.motion.set(i, clamped);
        changed = true;
    }
    return changed;
}

// Every integrator but Verlet, through its row of the table (integrator.hpp): one call shape, one file each in
// src/core/integrators/. All share compute_forces and the collision stage after them.
void MassSpring::step_velocity_integrator(Integrator integrator, double h, bool continues) {
    const ForceFunction forces = [this](const State& s, Vec3Array& f) { compute_forces(s, f); };
    const ForceFunction external = [this](const State& s, Vec3Array& f) {
        f.resize(s.size());
        if (plan_.external_forces()) {
            Vec3Array scratch;
            add_external_forces(s, f, scratch, nullptr);
        }
        if (grab_) f.add(grab_->particle, grab_force(s));
    };
    const Dynamics dynamics{forces, external, settings_.forces.gravity, settings_.springs.damping};
    IntegratorContext context{state_, topology_, settings_, dynamics, h, continues, *iterative_.data, {}, {}};
    context.frozen_external = [this](Vec3Array& f) {
        f.resize(state_.size());
        if (plan_.wind || plan_.contact) {
            Vec3Array scratch;
            add_external_forces(state_, f, scratch, nullptr, false);
        }
        if (grab_) f.add(grab_->particle, grab_force(state_));
    };
    const IntegratorInfo& info = integrator_info(integrator);
    if (!info.substep) return;  // Verlet: substep() runs the fast solver or the textbook path
    info.substep(context);
    if (info.reports_solve) {
        last_iterations_ = context.solve.iterations;
        last_residual_ = context.solve.residual;
    }
}

// Wind, contact and soft clips are summed on their own and added last, as the fast solver adds them, so both
// round alike.
void MassSpring::add_external_forces(const State& state, Vec3Array& force, Vec3Array& scratch,
                                     StepProfile* profile, bool holds) const {
    scratch.resize(state.size());
    if (plan_.wind) {
        StageTimer timer(profile, Stage::Wind);
        accumulate_wind_forces(topology_, state, settings_.forces, rest_area_, scratch);
    }
    if (plan_.contact) {
        StageTimer timer(profile, Stage::Contact);
        accumulate_contact_forces(state, settings_.colliders, scratch);
    }
    if (plan_.holds && holds) {
        StageTimer timer(profile, Stage::Clips);
        accumulate_hold_forces(topology_, state.position, scratch);
    }
    for (std::size_t i = 0; i < state.size(); ++i) force.add(i, scratch.get(i));
}

void MassSpring::compute_forces(const State& state, Vec3Array& force) const {
    force.resize(state.size());
    accumulate_spring_forces(topology_, state.position, settings_.springs, force);
    if (plan_.external_forces()) {
        Vec3Array external;
        add_external_forces(state, force, external, nullptr);
    }
    if (grab_) force.add(grab_->particle, grab_force(state));
}

void MassSpring::grab(std::size_t i, glm::vec3 target) {
    if (state_.pinned.at(i)) return;
    wake();
    if (!grab_ || grab_->particle != i) {
        grab_ = GrabSpring{i, target, grab_force_limit(i)};
        grab_external_ = Vec3Array{};
        grab_external_.resize(state_.size());
    }
    grab_->target = target;
}

// The cap: what stretches the particle's own springs by half their rest length, at least 10 m |g|.
float MassSpring::grab_force_limit(std::size_t i) const {
    float springs = 0.0f;
    for (const Spring& s : topology_.springs) {
        if (s.a == i || s.b == i) springs += stiffness_of(settings_.springs, s) * s.rest_length;
    }
    const float floor = 10.0f * state_.mass[i] * std::max(glm::length(settings_.forces.gravity), 9.81f);
    return std::max(0.5f * springs, floor);
}

void MassSpring::release_grab() {
    if (!grab_) return;
    grab_.reset();
    grab_external_ = Vec3Array{};
    wake();
}

glm::vec3 MassSpring::grab_force() const { return grab_ ? grab_force(state_) : glm::vec3(0.0f); }

glm::vec3 MassSpring::grab_force(const State& state) const { return grab_->force(state, substep_length()); }

// XPBD's residual is measured when asked, at the positions now (after collisions and limits): the step
// itself pays nothing for it.
double MassSpring::last_solver_residual() const {
    if (settings_.integration.integrator == Integrator::Xpbd && state_.integrator == Integrator::Xpbd) {
        const IterativeSolvers::Data& data = *iterative_.data;
        if (data.grid_xpbd_ran) return data.grid_xpbd->residual(state_.position);
        return xpbd_residual(state_.position, topology_, settings_.springs, data.xpbd);
    }
    return last_residual_;
}

void MassSpring::run_steps(long long steps) {
    for (long long s = 0; s < steps; ++s) {
        for (int i = 0; i < settings_.integration.substeps; ++i) substep();
    }
}

void MassSpring::restart(const std::vector<glm::dvec3>& velocity, double h) {
    history_stamp_ = 0;  // the velocities are new: a multistep integrator starts afresh
    const Integrator integrator = settings_.integration.integrator;
    state_.integrator = integrator;
    if (!integrator_info(integrator).keeps_velocity) {  // Verlet: motion = x - x_prev
        compute_forces(state_, force_);
        start_verlet(state_, velocity, force_, settings_.forces.gravity, settings_.springs.damping, h);
        return;
    }
    // The velocity integrators keep motion = v h.
    for (std::size_t i = 0; i < state_.size(); ++i) {
        state_.motion.set(i, state_.pinned[i] ? glm::dvec3(0.0) : velocity[i] * h);
    }
    state_.substep = h;
}

Particle MassSpring::particle(std::size_t i) const {
    const glm::dvec3 x = state_.position.get(i);
    return {glm::vec3(x), glm::vec3(x - state_.motion.get(i)), state_.mass[i], state_.pinned[i] != 0};
}

std::vector<glm::vec3> MassSpring::positions() const {
    std::vector<glm::vec3> p;
    positions(p);
    return p;
}

void MassSpring::positions(std::vector<glm::vec3>& out) const {
    out.resize(state_.size());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = glm::vec3(state_.position.get(i));
}

std::vector<glm::vec3> MassSpring::velocities() const {
    const std::vector<glm::dvec3> exact = velocities_in_double();
    return std::vector<glm::vec3>(exact.begin(), exact.end());
}

std::vector<glm::dvec3> MassSpring::velocities_in_double() const {
    if (sleep_.asleep()) return std::vector<glm::dvec3>(state_.size(), glm::dvec3(0.0));
    if (integrator_info(state_.integrator).keeps_velocity) {
        std::vector<glm::dvec3> v(state_.size(), glm::dvec3(0.0));
        if (state_.substep > 0.0) {
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
    const std::vector<glm::dvec3> v = velocities_in_double();
    const glm::dvec3 g(settings_.forces.gravity);
    for (std::size_t i = 0; i < state_.size(); ++i) {
        if (state_.pinned[i]) continue;
        const double m = state_.mass[i];
        e.kinetic += 0.5 * m * glm::dot(v[i], v[i]);
        e.gravity_potential -= m * glm::dot(g, state_.position.get(i));
    }
    e.spring_potential = spring_potential_energy(topology_, state_.position, settings_.springs);
    if (plan_.contact) e.contact_potential = contact_potential_energy(state_, settings_.colliders);
    return e;
}

glm::vec3 MassSpring::momentum() const {
    const std::vector<glm::dvec3> v = velocities_in_double();
    glm::dvec3 p(0.0);
    for (std::size_t i = 0; i < state_.size(); ++i) {
        if (!state_.pinned[i]) p += double(state_.mass[i]) * v[i];
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

void MassSpring::set_masses(std::span<const float> mass) {
    const std::size_t n = state_.size();
    if (mass.size() != n) {
        throw std::invalid_argument("MassSpring::set_masses: " + std::to_string(mass.size()) + " masses for " +
                                    std::to_string(n) + " particles");
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (state_.pinned[i] != kAbsent && !(std::isfinite(mass[i]) && mass[i] > 0.0f)) {
            throw std::invalid_argument("MassSpring::set_masses: particle " + std::to_string(i) + " would have mass " +
                                        std::to_string(mass[i]) + " kg; allowed: finite and > 0");
        }
    }
    if (std::equal(mass.begin(), mass.end(), state_.mass.begin())) return;
    for (std::size_t i = 0; i < n; ++i) {
        if (state_.pinned[i] == kAbsent) continue;
        state_.mass[i] = mass[i];
        state_.inverse_mass[i] = state_.pinned[i] ? 0.0f : 1.0f / mass[i];
    }
    // The motion (x - x_prev, or v h) is kept: velocities carry over, and the new masses act from the next
    // substep. The projective matrix holds the masses; the stability limit and the grab's cap follow them.
    iterative_.invalidate();
    if (grab_) grab_->force_limit = grab_force_limit(grab_->particle);
    wake();
    setup_stamp_ = next_stamp();
}

void MassSpring::set_pinned(std::size_t i, bool pinned) {
    if (state_.pinned.at(i) == kAbsent) return;  // outside the cloth's shape: no particle to pin or free
    if (pinned && grab_ && grab_->particle == i) release_grab();
    wake();
    stamp_ = next_stamp();
    setup_stamp_ = next_stamp();
    state_.pinned.at(i) = pinned ? kPinned : 0;
    state_.inverse_mass[i] = pinned ? 0.0f : 1.0f / state_.mass[i];
    if (!pinned) std::erase_if(pin_targets_, [&](const PinTarget& t) { return t.particle == i; });
    if (pinned) state_.motion.set(i, glm::dvec3(0.0));
    iterative_.invalidate();  // its matrix is over the free particles
    rebuild_tethers();  // the pins the cloth hangs from changed
    replan();
}

void MassSpring::move_pinned(std::size_t i, glm::vec3 position) {
    if (state_.pinned.at(i) != kPinned) return;
    wake();
    stamp_ = next_stamp();
    state_.position.set(i, glm::dvec3(position));
    state_.motion.set(i, glm::dvec3(0.0));
}

void MassSpring::drag_pin(std::size_t i, glm::vec3 target) {
    if (state_.pinned.at(i) != kPinned) return;
    wake();
    const glm::dvec3 to(target);
    // The whole way in one step of integration.dt, at most kPinStepPerSubstep spacings a substep.
    const double way = glm::length(to - state_.position.get(i));
    const double reach = std::min(way / std::max(settings_.integration.substeps, 1), kPinStepPerSubstep * spacing_);
    for (PinTarget& t : pin_targets_) {
        if (t.particle == i) {
            t.target = to;
            t.reach = reach;
            return;
        }
    }
    pin_targets_.push_back({i, to, reach});
}

std::optional<glm::vec3> MassSpring::pin_target(std::size_t i) const {
    for (const PinTarget& t : pin_targets_) {
        if (t.particle == i) return glm::vec3(t.target);
    }
    return std::nullopt;
}

bool MassSpring::move_dragged_pins() {
    bool moved = false;
    std::erase_if(pin_targets_, [&](const PinTarget& t) {
        const glm::dvec3 x = state_.position.get(t.particle);
        const glm::dvec3 d = t.target - x;
        const double length = glm::length(d);
        if (!std::isfinite(length)) return true;  // a NaN target is dropped where the pin is
        const bool arrives = !(length > t.reach * (1.0 + 1e-9));
        glm::dvec3 to = arrives ? t.target : x + d * (t.reach / length);
        to = within_reach_of_pins(t.particle, x, to);
        const double step = glm::length(to - x);
        moved = moved || step > 0.0;
        state_.position.set(t.particle, to);
        return arrives || !(step > 1e-6 * t.reach);  // arrived, or held at the other pins' reach
    });
    return moved;
}

// Cyclic projection onto the balls around the other pins (radius (1 + tether_strain or kPinDragStretch) x the
// rest distance): their intersection is convex and holds `from`, where the pin is, so a few rounds land in it
// or near; a point still outside any ball (by more than rounding) leaves the pin where it is.
glm::dvec3 MassSpring::within_reach_of_pins(std::size_t i, glm::dvec3 from, glm::dvec3 x) const {
    const double stretch = 1.0 + (plan_.tethers ? double(settings_.springs.tether_strain) : kPinDragStretch);
    const glm::dvec3 rest = rest_position_.get(i);
    // The other pins and how far from each the pin may go, found once.
    struct Ball {
        glm::dvec3 centre;
        double radius;
    };
    std::vector<Ball> balls;
    for (std::size_t j = 0; j < state_.size(); ++j) {
        if (j != i && state_.pinned[j] == kPinned) {
            balls.push_back({state_.position.get(j), stretch * glm::length(rest - rest_position_.get(j))});
        }
    }
    auto outside = [](const Ball& b, glm::dvec3 p) { return glm::length(p - b.centre) > b.radius * (1.0 + 1e-9); };
    for (int round = 0; round < 4; ++round) {
        bool moved = false;
        for (const Ball& b : balls) {
            if (!outside(b, x)) continue;
            x = b.centre + (x - b.centre) * (b.radius / glm::length(x - b.centre));
            moved = true;
        }
        if (!moved) return x;
    }
    for (const Ball& b : balls) {
        if (outside(b, x)) return from;
    }
    return x;
}

void MassSpring::set_particle(std::size_t i, glm::vec3 position, glm::vec3 velocity) {
    wake();
    stamp_ = next_stamp();
    std::vector<glm::dvec3> v = velocities_in_double();
    state_.position.set(i, glm::dvec3(position));
    v.at(i) = state_.pinned[i] ? glm::dvec3(0.0) : glm::dvec3(velocity);
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
    // The solid shapes' boxes, then the planes' heights (unbounded sideways, they bound only y).
    const ColliderSettings& c = sim.settings().colliders;
    for (const Collider& collider : c.shapes) {
        if (!collider.enabled || is_half_space(collider)) continue;
        const Box box = bounds(collider);
        lo = glm::min(lo, box.lo);
        hi = glm::max(hi, box.hi);
    }
    if (!(lo.x <= hi.x)) lo = hi = glm::vec3(0.0f);
    for (const Collider& collider : c.shapes) {
        if (!collider.enabled || !is_half_space(collider)) continue;
        const Box box = bounds(collider);
        lo.y = std::min(lo.y, box.lo.y);
        hi.y = std::max(hi.y, box.hi.y);
    }
}

}  // namespace clothsim
