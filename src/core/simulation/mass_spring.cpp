#include "simulation/mass_spring_internals.hpp"

#include "clothsim/collider_motion.hpp"
#include "collision/colliders.hpp"
#include "model/tearing.hpp"
#include "model/tethers.hpp"
#include "model/forces.hpp"
#include "integrators/fast_solver.hpp"
#include "integrators/grid_xpbd.hpp"
#include "integrators/integrator_step.hpp"
#include "integrators/integrators.hpp"
#include "integrators/work_team.hpp"
#include "collision/penalty_contact.hpp"
#include "integrators/projective.hpp"
#include "integrators/verlet.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <unordered_map>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {

// A mesh cloth's per-particle stages on the team (integration, tethers) in pieces of this many particles: enough
// work to pay for a claim.
constexpr std::size_t kTeamPiece = 1024;  // as the element gather's sum: each thread finds its particles in its cache

// Stamps are unique across all simulations, so a copy keeps its stamp and a new cloth never reuses one.
std::uint64_t next_stamp() {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
}

}  // namespace

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
    in_->blocks.start = block_starts(n, topology_.rows, topology_.cols);
    rest_position_ = state_.position;  // the builder makes the cloth flat, at rest
    spacing_ = particle_spacing(topology_);
    in_->tethers = build_tethers(topology_, state_, rest_position_);
    cells_at_start_ = cells_at_start(topology_, n);
    surface_ = build_cloth_surface(topology_, rest_position_, cells_at_start_);
    replan();
    track_collider_motion();
    restart(initial_velocity.empty() ? std::vector<glm::dvec3>(n, glm::dvec3(0.0))
                                     : std::vector<glm::dvec3>(initial_velocity.begin(), initial_velocity.end()),
            substep_length());
    push_out_of_jumped_meshes({});  // a cloth built inside a mesh starts outside it
    stamp_ = next_stamp();
    setup_stamp_ = next_stamp();
    topology_stamp_ = next_stamp();
}

void MassSpring::Internals::invalidate_iterative() {
    iterative.projective.invalidate_matrix();
    iterative.grid_xpbd_current = false;
}

MassSpring::InternalsPtr::InternalsPtr() : p_(std::make_unique<Internals>()) {}
MassSpring::InternalsPtr::InternalsPtr(const InternalsPtr& other) : p_(std::make_unique<Internals>(*other.p_)) {}
MassSpring::InternalsPtr& MassSpring::InternalsPtr::operator=(const InternalsPtr& other) {
    if (this == &other) return *this;
    if (p_) *p_ = *other.p_;  // member by member: the vectors keep their storage
    else p_ = std::make_unique<Internals>(*other.p_);  // a moved-from simulation has none to keep
    return *this;
}
MassSpring::InternalsPtr::InternalsPtr(InternalsPtr&&) noexcept = default;
MassSpring::InternalsPtr& MassSpring::InternalsPtr::operator=(InternalsPtr&&) noexcept = default;
MassSpring::InternalsPtr::~InternalsPtr() = default;

const CollisionBlocks& collision_blocks(const MassSpring& sim) { return sim.in_->blocks; }

MassSpring::~MassSpring() = default;
MassSpring::MassSpring(const MassSpring&) = default;
MassSpring& MassSpring::operator=(const MassSpring&) = default;
MassSpring::MassSpring(MassSpring&&) noexcept = default;
MassSpring& MassSpring::operator=(MassSpring&&) noexcept = default;

bool MassSpring::fast_solver_available() const { return in_->fast.has_value(); }
std::size_t MassSpring::tether_count() const { return in_->tethers.size(); }
bool MassSpring::asleep() const { return in_->sleep.asleep(); }
double MassSpring::calm_seconds() const { return in_->sleep.calm_seconds(); }
std::optional<std::size_t> MassSpring::grabbed() const {
    return in_->grab ? std::optional<std::size_t>(in_->grab->particle) : std::nullopt;
}
float MassSpring::grab_force_limit() const { return in_->grab ? in_->grab->force_limit : 0.0f; }

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
        const IntegratorCaches& xpbd = in_->iterative;
        if (plan_.path == StepPath::TextbookVerlet && mesh_team_threads() > 0) return mesh_team_threads();
        if (!last_step_fast()) return 1;
        if (xpbd.grid_xpbd_ran) return xpbd.grid_xpbd->last_threads();
        return xpbd.coloured_xpbd->last_threads();
    }
    const bool set_aside = settings_.solver.threads == 0 && in_->fast->team_set_aside();
    return set_aside ? 1 : in_->fast->effective_threads(settings_.solver.threads);
}

bool MassSpring::last_step_fast() const {
    if (plan_.path == StepPath::FastVerlet) return true;
    if (plan_.path == StepPath::TextbookVerlet && mesh_team_threads() > 0) return true;  // the element gather
    return settings_.integration.integrator == Integrator::Xpbd && state_.integrator == Integrator::Xpbd &&
           (in_->iterative.grid_xpbd_ran || in_->iterative.coloured_xpbd_ran);
}

double MassSpring::substep_length() const {
    return static_cast<double>(settings_.integration.dt) / settings_.integration.substeps;
}

void MassSpring::apply(const SimulationSettings& settings) {
    if (settings == settings_) return;
    // The projective solver's matrix holds the stiffness, the substep and the damping.
    if (settings.springs != settings_.springs || settings.integration != settings_.integration) {
        in_->invalidate_iterative();
    }
    // Soft clips hold in proportion to the sheet's stiffness.
    if (settings.springs.structural != settings_.springs.structural) {
        for (SoftClipSpring& hold : topology_.clip_springs) {
            if (hold.share_u > 0.0f || hold.share_v > 0.0f) hold.stiffness = hold.stiffness_for(settings.springs.structural);
        }
    }
    const bool colliders_changed = settings.colliders != settings_.colliders;
    std::vector<Collider> before;
    if (colliders_changed) before = colliders();
    settings_ = settings;
    if (in_->grab) in_->grab->force_limit = grab_force_limit(in_->grab->particle);  // it follows the springs' k
    replan();
    track_collider_motion();
    if (colliders_changed) push_out_of_jumped_meshes(before);
    wake();  // a changed setting (a collider moved, wind, a slider) is something driving the cloth
    // Self-collision's list and budget say nothing of what the cloth did while the stage was off or set
    // otherwise: it tests afresh at its next substep.
    if (in_->self_collision) in_->self_collision->invalidate();
    setup_stamp_ = next_stamp();
}

// Whether a collider moves, and the posed list made to match the settings' (collider_motion.hpp).
void MassSpring::track_collider_motion() {
    const auto& shapes = settings_.colliders.shapes;
    in_->colliders_move = colliders_move(settings_.colliders);
    if (!in_->colliders_move) {
        in_->posed = ColliderSettings{};
        in_->surfaces.clear();
        return;
    }
    in_->posed = settings_.colliders;
    in_->surfaces.assign(shapes.size(), SurfaceMotion{});
    pose_colliders(state_.time, state_.time);
}

void MassSpring::push_out_of_jumped_meshes(const std::vector<Collider>& before) {
    const std::vector<Collider>& now = colliders_now().shapes;
    const float thickness = settings_.colliders.thickness;
    // A drag or a new velocity re-expresses the pose at this time through the fields at time 0 (with_velocity),
    // which may round it by a float ulp: no jump. A move of 1% of the thickness or more is one.
    auto jumped = [&](std::size_t i) {
        const auto* was = i < before.size() && before[i].enabled ? std::get_if<MeshCollider>(&before[i].shape) : nullptr;
        const MeshCollider& is = std::get<MeshCollider>(now[i].shape);
        return !was || was->mesh != is.mesh || was->scale != is.scale ||
               glm::length(was->rotation - is.rotation) > 1e-3f || glm::length(was->position - is.position) >= 0.01f * thickness;
    };
    std::size_t moved = 0;
    for (std::size_t i = 0; i < now.size(); ++i) {
        if (std::holds_alternative<MeshCollider>(now[i].shape) && jumped(i)) {
            moved += push_out_of_mesh(state_, now[i], thickness);
        }
    }
    if (moved == 0) return;
    stamp_ = next_stamp();
    in_->blocks.moved_outside_motion();
}

// The moving colliders posed at t1, and their surfaces' motion over [t0, t1].
void MassSpring::pose_colliders(double t0, double t1) const {
    const auto& shapes = settings_.colliders.shapes;
    for (std::size_t i = 0; i < shapes.size(); ++i) {
        if (!shapes[i].motion.moves()) continue;
        pose_at(shapes[i], t1, in_->posed.shapes[i]);
        in_->surfaces[i] = surface_motion(shapes[i], t0, t1);
    }
    in_->posed_time = t1;
}

const ColliderSettings& MassSpring::colliders_now() const {
    return in_->colliders_move ? in_->posed : settings_.colliders;
}

const std::vector<Collider>& MassSpring::colliders() const {
    if (in_->colliders_move && in_->posed_time != state_.time) pose_colliders(state_.time, state_.time);
    return colliders_now().shapes;
}

bool MassSpring::move_collider(std::size_t i, glm::vec3 to, double seconds) {
    if (i >= settings_.colliders.shapes.size() || !std::isfinite(to.x) || !std::isfinite(to.y) || !std::isfinite(to.z)) {
        return false;
    }
    SimulationSettings s = settings_;
    Collider& c = s.colliders.shapes[i];
    const double t = state_.time;
    Collider now = c;
    pose_at(c, t, now);
    const glm::dvec3 shift = glm::dvec3(to) - pivot(now);
    if (seconds > 0.0) {
        c = with_velocity(c, t, glm::vec3(shift / seconds), t + seconds);
    } else {
        c = with_velocity(c, t, glm::vec3(0.0f), INFINITY);
        translate(c, shift);
    }
    apply(s);
    return true;
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
    if (in_->sleep.asleep()) {
        state_.time += h;
        ++profile_.slept_substeps;
        return;
    }
    StepProfile* profile = profiling_ ? &profile_ : nullptr;
    if (in_->colliders_move) pose_colliders(state_.time, state_.time + h);
    in_->blocks.positions_moving();
    const Integrator integrator = settings_.integration.integrator;
    if (h != state_.substep || integrator != state_.integrator) restart(velocities_in_double(), h);
    const bool continues = stamp_ == history_stamp_;  // nothing but the last step moved the cloth since
    if (!continues) in_->blocks.moved_outside_motion();    // an edit may have moved particles
    // A dragged pin moves outside the motions the broad phase and self-collision count.
    if (!in_->pin_targets.empty() && move_dragged_pins()) {
        in_->blocks.moved_outside_motion();
        if (in_->self_collision) in_->self_collision->invalidate();
    }
    // Self-collision's list of near pairs holds while only steps move the particles (self_collision.hpp).
    if (!continues && in_->self_collision) in_->self_collision->invalidate();

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
    const bool collided = collide(profile, swept_bounds ? &in_->motion_bounds : nullptr);
    const MotionBounds* known = swept_bounds && !collided ? &in_->motion_bounds : nullptr;
    // Moves outside the motions, which self-collision's budget does not count: a collider's push now, what
    // the stages after the last substep's self stage did, and the steps of RK4 and projective, whose motion
    // (v h at the substep's end) is not the substep's displacement.
    const bool displaced = !integrator_info(integrator).motion_is_displacement;
    const bool self_moved =
        plan_.self_collision && collide_self(profile, known, collided || in_->moved_uncounted || displaced);
    in_->moved_uncounted = false;
    if (self_moved || plan_.tethers || plan_.strain_limit || plan_.speed_limit) {
        // Without a limit stage between them, the tethers' job also boxes the blocks, band by band, while the
        // rows it projected are in its core's cache: one hand-off a substep instead of two.
        std::optional<BlockBounds> boxed;
        if (plan_.tethers) {
            StageTimer timer(profile, Stage::Tethers);
            if (boxes_on_team() && !plan_.strain_limit && !plan_.speed_limit) {
                if (self_moved) in_->blocks.moved_outside_motion();
                boxed = block_bounds_for(colliders_now(), in_->blocks);
            }
            tethers_at_limit_ = apply_tethers(boxed ? &*boxed : nullptr);
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
        if (self_moved || limited) in_->blocks.moved_outside_motion();  // pushes and limits; tethers stay inside it
        if (plan_.tethers && tethers_at_limit_ > 0 && in_->blocks.carried_valid) {
            // A tether keeps its particle in the carried box but takes the outward part of its motion, which
            // moves the start of its path (x - motion, where the swept tests begin) by at most that motion.
            in_->blocks.widen_carried(swept_bounds && !collided ? in_->motion_bounds.largest() : NAN);
        }
        in_->blocks.positions_moving();
        in_->blocks.boxes_current = box_blocks_on_team(profile, boxed ? &*boxed : nullptr);
        const bool pushed = collide(profile);  // a push or a correction must not leave a particle inside a collider
        in_->moved_uncounted = pushed || limited || (plan_.tethers && tethers_at_limit_ > 0);
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
            in_->sleep.check(state_, settings_.solver, h, !in_->pin_targets.empty());  // a pin on its way drives the cloth
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
        if (in_->grab) force_.add(in_->grab->particle, grab_force(state_));
        external = &force_;
    } else if (in_->grab || plan_.soft_clips) {
        // Forces on a few particles: written into an array that stays zero elsewhere, instead of summing a
        // whole array every substep (soft clips hold tens of particles of thousands).
        if (grab_external_.size() != state_.size()) grab_external_.resize(state_.size());
        if (in_->grab) grab_external_.set(in_->grab->particle, glm::vec3(0.0f));
        if (plan_.soft_clips) {
            StageTimer timer(profile, Stage::SoftClips);
            for (const SoftClipSpring& hold : topology_.clip_springs) grab_external_.set(hold.particle, glm::vec3(0.0f));
            accumulate_soft_clip_forces(topology_, state_.position, grab_external_);
        }
        if (in_->grab) grab_external_.add(in_->grab->particle, grab_force(state_));
        external = &grab_external_;
    }
    const bool boxes = plan_.colliders && settings_.solver.broad_phase;
    if (boxes) in_->blocks.bounds = block_bounds_for(colliders_now(), in_->blocks);
    {
        StageTimer timer(profile, Stage::Fast);
        static_assert(CollisionBlocks::kBandUnions == FastSolver::kMaxBands);
        in_->fast->step(state_, settings_, plan_.spring_mask(), external, h, damping_rate(),
                        boxes ? &in_->blocks.boxes : nullptr,
                        sweep_takes_motion_bounds() ? &in_->motion_bounds : nullptr, in_->blocks.bounds,
                        boxes ? in_->blocks.band_union.data() : nullptr);
    }
    in_->blocks.boxes_current = boxes;
    in_->blocks.band_unions = boxes;
    in_->blocks.current = false;  // the cloth's box is the union, made by the collision stage
}

void MassSpring::step_textbook(double h, StepProfile* profile) {
    force_.resize(state_.size());
    if (plan_.any_springs()) {
        StageTimer timer(profile, Stage::Springs);
        // A mesh cloth's fast path: the same sums on the team (element_gather.hpp); the textbook method is the
        // list, on one thread, the oracle.
        if (const int threads = mesh_team_threads(); threads > 0) {
            gather_spring_forces(topology_, *in_->gather, state_.position, settings_.springs, force_, threads);
        } else {
            accumulate_spring_forces(topology_, state_.position, settings_.springs, force_);
        }
    }
    if (plan_.external_forces()) add_external_forces(state_, force_, external_, profile);
    if (in_->grab) force_.add(in_->grab->particle, grab_force(state_));
    {
        StageTimer timer(profile, Stage::Integrate);
        if (const int threads = mesh_team_threads(); threads > 0) {
            WorkTeam::shared().run_pieces(threads, state_.size(), kTeamPiece, [&](std::size_t first, std::size_t last) {
                integrate_verlet(state_, force_, settings_.forces.gravity, damping_rate(), h, first, last);
            });
            state_.substep = h;
        } else {
            integrate_verlet(state_, force_, settings_.forces.gravity, damping_rate(), h);
        }
    }
}

int MassSpring::mesh_team_threads() const {
    if (!in_->gather || settings_.solver.method != SolverMethod::Fast) return 0;
    return settings_.solver.threads > 0 ? settings_.solver.threads : WorkTeam::cores();
}

// On the fast path the tethers run on the fast solver's threads, each on the band of rows it has just swept, whose
// particles are in that core's caches (one thread over the whole cloth would move the other core's band to
// it and back every substep). Particles project independently (tethers.hpp), so the result is the same on any
// number of threads.
std::size_t MassSpring::apply_tethers(const BlockBounds* boxes) {
    const double strain = settings_.springs.tether_strain;
    if (const int threads = mesh_team_threads(); threads > 0 && plan_.path == StepPath::TextbookVerlet) {
        // A mesh cloth's tethers in pieces of particles on the team (sorted by particle: a piece's are a run).
        std::vector<std::size_t>& active = in_->tether_pieces;
        active.assign(static_cast<std::size_t>(WorkTeam::pieces(state_.size(), kTeamPiece)), 0);
        WorkTeam::shared().run_pieces(threads, state_.size(), kTeamPiece, [&](std::size_t first, std::size_t last) {
            active[first / kTeamPiece] = project_tethers(state_, in_->tethers, strain,
                                                         first_tether_from(in_->tethers, static_cast<std::uint32_t>(first)),
                                                         first_tether_from(in_->tethers, static_cast<std::uint32_t>(last)));
        });
        std::size_t total = 0;
        for (std::size_t a : active) total += a;
        return total;
    }
    if (plan_.path != StepPath::FastVerlet || !in_->fast) return project_tethers(state_, in_->tethers, strain);
    std::array<std::size_t, 64> active{};
    const auto cols = static_cast<std::uint32_t>(topology_.cols);
    if (boxes) start_boxes(*boxes);
    in_->fast->for_each_band([&](int band, int begin, int end) {
        const std::size_t first = first_tether_from(in_->tethers, static_cast<std::uint32_t>(begin) * cols);
        const std::size_t last = first_tether_from(in_->tethers, static_cast<std::uint32_t>(end) * cols);
        active[static_cast<std::size_t>(band)] = project_tethers(state_, in_->tethers, strain, first, last);
        if (boxes) box_rows(band, begin, end, *boxes);
    });
    std::size_t total = 0;
    for (std::size_t a : active) total += a;
    return total;
}

bool MassSpring::boxes_on_team() const {
    return plan_.path == StepPath::FastVerlet && in_->fast && plan_.colliders && settings_.solver.broad_phase;
}

// The same split for the boxes of the collision broad phase's blocks (block_starts' grid layout, row by
// row), which the collision stage would otherwise make again block by block on one thread. Boxes the
// tethers' job made stand while the bounds they were made with are still the ones to use: a tether at its
// limit widens the carried box, which may bring a solid within reach and call for whole boxes (which the
// collision stage would otherwise make, on one thread).
bool MassSpring::box_blocks_on_team(StepProfile* profile, const BlockBounds* made) {
    if (!boxes_on_team()) return false;
    const BlockBounds bounds = block_bounds_for(colliders_now(), in_->blocks);
    if (made && *made == bounds) return true;
    StageTimer timer(profile, Stage::BroadPhase);
    start_boxes(bounds);
    in_->fast->for_each_band([&](int band, int begin, int end) { box_rows(band, begin, end, bounds); });
    return true;
}

void MassSpring::start_boxes(BlockBounds bounds) {
    in_->blocks.bounds = bounds;
    in_->blocks.boxes.resize(static_cast<std::size_t>(topology_.rows) * blocks_per_row(topology_.cols));
    in_->blocks.band_union.fill(Box{});  // bands that box no row stay empty
    in_->blocks.band_unions = true;
}

void MassSpring::box_rows(int band, int begin, int end, BlockBounds bounds) {
    const int cols = topology_.cols;
    const std::size_t per_row = blocks_per_row(cols);
    Box* first = in_->blocks.boxes.data() + static_cast<std::size_t>(begin) * per_row;
    for (int r = begin; r < end; ++r) {
        row_block_bounds(state_.position, static_cast<std::size_t>(r) * cols, static_cast<std::size_t>(cols),
                         in_->blocks.boxes.data() + static_cast<std::size_t>(r) * per_row, bounds);
    }
    in_->blocks.band_union[static_cast<std::size_t>(band)] = union_of(first, static_cast<std::size_t>(end - begin) * per_row);
}

bool MassSpring::sweep_takes_motion_bounds() const {
    const bool swept_boxes = settings_.solver.broad_phase && plan_.solids;
    return plan_.self_collision || swept_boxes;
}

bool MassSpring::collide(StepProfile* profile, const MotionBounds* motion) {
    if (!plan_.colliders) {
        in_->blocks.moved_outside_motion();  // not grown while no stage reads it
        return false;
    }
    return collide_stage(state_, colliders_now(), settings_.solver.broad_phase, in_->blocks, profile, solver_threads(),
                         motion, in_->colliders_move ? in_->surfaces.data() : nullptr);
}

// The cloth against itself (self_collision.hpp), built the first time it runs.
bool MassSpring::collide_self(StepProfile* profile, const MotionBounds* known, bool uncounted) {
    StageTimer timer(profile, Stage::SelfCollision);
    if (!in_->self_collision) in_->self_collision.emplace(topology_, rest_position_);
    const SelfCollisionCounts counts = in_->self_collision->collide(state_, settings_.collision, rest_position_, known, uncounted);
    if (profile) {
        if (counts.tiles > 0) ++profile->self_tests;
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
    in_->invalidate_iterative();
    if (in_->self_collision) in_->self_collision->update_neighbours(topology_, rest_position_);
    rebuild_tethers();
    surface_ = build_cloth_surface(topology_, rest_position_, cells_at_start_);
    replan();
    setup_stamp_ = next_stamp();
    topology_stamp_ = next_stamp();
}

// The fast solver's layout of the current topology, or none when it is no grid.
void MassSpring::build_fast_solver() {
    in_->fast.reset();
    in_->gather.reset();
    if (topology_.mesh) in_->gather = ElementGather::for_topology(topology_);
    if (auto solver = FastSolver::for_topology(topology_)) {
        in_->fast = std::move(*solver);
    }
}

// Tethers to the current pins; after a tear only within each piece (a piece torn off falls freely).
void MassSpring::rebuild_tethers() {
    in_->tethers = build_tethers(topology_, state_, rest_position_);
    tethers_at_limit_ = 0;
    if (broken_springs_ == 0 || in_->tethers.empty()) return;
    const std::vector<std::uint32_t> piece = connected_pieces(topology_, state_.size());
    Tethers kept;
    for (std::size_t t = 0; t < in_->tethers.size(); ++t) {
        if (piece[in_->tethers.particle[t]] != piece[in_->tethers.anchor[t]]) continue;
        kept.particle.push_back(in_->tethers.particle[t]);
        kept.anchor.push_back(in_->tethers.anchor[t]);
        kept.rest.push_back(in_->tethers.rest[t]);
    }
    in_->tethers = std::move(kept);
}

void MassSpring::replan() {
    plan_ = plan_step(topology_, settings_, in_->fast.has_value(), !in_->tethers.empty());
}

void MassSpring::wake() {
    substeps_since_check_ = 0;
    if (in_->sleep.wake()) restart(std::vector<glm::dvec3>(state_.size(), glm::dvec3(0.0)), substep_length());
}

void MassSpring::stop() {
    wake();
    restart(std::vector<glm::dvec3>(state_.size(), glm::dvec3(0.0)), substep_length());
}

void MassSpring::set_settle_damping(double rate) {
    if (!(rate >= 0.0) || !std::isfinite(rate)) throw std::invalid_argument("settle damping must be finite and >= 0");
    settle_damping_ = rate;
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
        if (in_->grab) f.add(in_->grab->particle, grab_force(s));
    };
    const Dynamics dynamics{forces, external, settings_.forces.gravity, static_cast<float>(damping_rate())};
    IntegratorContext context{state_, topology_, settings_, dynamics, h, continues, in_->iterative, {}, {}};
    context.frozen_external = [this](Vec3Array& f) {
        f.resize(state_.size());
        if (plan_.wind || plan_.contact) {
            Vec3Array scratch;
            add_external_forces(state_, f, scratch, nullptr, false);
        }
        if (in_->grab) f.add(in_->grab->particle, grab_force(state_));
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
        accumulate_contact_forces(state, colliders_now(), scratch);
    }
    if (plan_.soft_clips && holds) {
        StageTimer timer(profile, Stage::SoftClips);
        accumulate_soft_clip_forces(topology_, state.position, scratch);
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
    if (in_->grab) force.add(in_->grab->particle, grab_force(state));
}

void MassSpring::grab(std::size_t i, glm::vec3 target) {
    if (state_.pinned.at(i)) return;
    wake();
    if (!in_->grab || in_->grab->particle != i) {
        in_->grab = GrabSpring{i, target, grab_force_limit(i)};
        grab_external_ = Vec3Array{};
        grab_external_.resize(state_.size());
    }
    in_->grab->target = target;
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
    if (!in_->grab) return;
    in_->grab.reset();
    grab_external_ = Vec3Array{};
    wake();
}

glm::vec3 MassSpring::grab_force() const { return in_->grab ? grab_force(state_) : glm::vec3(0.0f); }

glm::vec3 MassSpring::grab_force(const State& state) const { return in_->grab->force(state, substep_length()); }

// XPBD's residual is measured when asked, at the positions now (after collisions and limits): the step
// itself pays nothing for it.
double MassSpring::last_solver_residual() const {
    if (settings_.integration.integrator == Integrator::Xpbd && state_.integrator == Integrator::Xpbd) {
        const IntegratorCaches& data = in_->iterative;
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
        start_verlet(state_, velocity, force_, settings_.forces.gravity, damping_rate(), h);
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
    if (in_->sleep.asleep()) return std::vector<glm::dvec3>(state_.size(), glm::dvec3(0.0));
    if (integrator_info(state_.integrator).keeps_velocity) {
        std::vector<glm::dvec3> v(state_.size(), glm::dvec3(0.0));
        if (state_.substep > 0.0) {
            for (std::size_t i = 0; i < v.size(); ++i) v[i] = state_.motion.get(i) / state_.substep;
        }
        return v;
    }
    Vec3Array force;
    compute_forces(state_, force);
    return verlet_velocities(state_, force, settings_.forces.gravity, damping_rate());
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
    if (plan_.contact) e.contact_potential = contact_potential_energy(state_, colliders_now());
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
    in_->invalidate_iterative();
    if (in_->grab) in_->grab->force_limit = grab_force_limit(in_->grab->particle);
    wake();
    setup_stamp_ = next_stamp();
}

void MassSpring::set_spring_weights(std::span<const Spring> from) {
    auto key = [](std::uint32_t a, std::uint32_t b) {
        return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
    };
    std::unordered_map<std::uint64_t, float> weight;
    weight.reserve(from.size());
    for (const Spring& s : from) weight[key(s.a, s.b)] = s.weight;
    std::vector<float> next(topology_.springs.size());
    for (std::size_t j = 0; j < next.size(); ++j) {
        const Spring& s = topology_.springs[j];
        const auto found = weight.find(key(s.a, s.b));
        if (found == weight.end() || !(std::isfinite(found->second) && found->second >= 0.0f)) {
            throw std::invalid_argument("MassSpring::set_spring_weights: spring " + std::to_string(j) + " (" +
                                        std::to_string(s.a) + ", " + std::to_string(s.b) + ") has " +
                                        (found == weight.end() ? "no match" : "weight " + std::to_string(found->second)) +
                                        "; allowed: finite and >= 0");
        }
        next[j] = found->second;
    }
    bool changed = false;
    for (std::size_t j = 0; j < next.size(); ++j) {
        changed = changed || topology_.springs[j].weight != next[j];
        topology_.springs[j].weight = next[j];
    }
    if (!changed) return;
    // The projective matrix, the stability limit and the mesh's element gather hold the springs' k; the cloth
    // wakes to feel them.
    if (in_->gather) in_->gather->set_weights(topology_);
    in_->invalidate_iterative();
    replan();
    wake();
    setup_stamp_ = next_stamp();
}

void MassSpring::set_pinned(std::size_t i, bool pinned) {
    if (state_.pinned.at(i) == kAbsent) return;  // outside the cloth's shape: no particle to pin or free
    if (pinned && in_->grab && in_->grab->particle == i) release_grab();
    wake();
    stamp_ = next_stamp();
    setup_stamp_ = next_stamp();
    state_.pinned.at(i) = pinned ? kPinned : 0;
    state_.inverse_mass[i] = pinned ? 0.0f : 1.0f / state_.mass[i];
    if (!pinned) std::erase_if(in_->pin_targets, [&](const Internals::PinTarget& t) { return t.particle == i; });
    if (pinned) state_.motion.set(i, glm::dvec3(0.0));
    in_->invalidate_iterative();  // its matrix is over the free particles
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
    for (Internals::PinTarget& t : in_->pin_targets) {
        if (t.particle == i) {
            t.target = to;
            t.reach = reach;
            return;
        }
    }
    in_->pin_targets.push_back({i, to, reach});
}

std::optional<glm::vec3> MassSpring::pin_target(std::size_t i) const {
    for (const Internals::PinTarget& t : in_->pin_targets) {
        if (t.particle == i) return glm::vec3(t.target);
    }
    return std::nullopt;
}

bool MassSpring::move_dragged_pins() {
    bool moved = false;
    std::erase_if(in_->pin_targets, [&](const Internals::PinTarget& t) {
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
