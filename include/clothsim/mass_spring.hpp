// MassSpring: a cloth of particles joined by Hooke springs, advanced by one of six integrators (position
// Verlet, the default; symplectic Euler, RK4, implicit Euler, XPBD, projective: the table in integrator.hpp).
//
// The pipeline of one substep is MassSpring::substep() in src/core/simulation/mass_spring.cpp; read it top to bottom:
// accumulate forces (springs, wind, penalty contact, the user's grab), integrate (gravity and damping inside),
// collide (the projection contact with the scene's list of shapes: collider.hpp), pull tethered particles back to their pins, limit strain and speed, and once per step see whether
// the cloth may sleep. colliders.contact picks penalty contact (a force) or projection (a stage after). Which of these stages
// run is planned from the settings (step_plan.hpp); each one that runs is timed (step_profile.hpp).
// Topology is fixed at construction. MassSpring owns the live settings: apply() changes them (stiffness,
// damping, forces, colliders, dt, substeps), replans the stages and wakes the cloth at that point, and the
// next substep runs them. How wall or simulated time becomes steps (fixed step, auto substeps, the guard)
// is the Stepper's (stepper.hpp).
//
// Sleeping (as Box2D's islands sleep): when solver.sleep_speed > 0 and the air is still, the cloth is
// checked at the end of every step: each free particle's displacement since the last check, over the time
// between, is its speed. Once every speed has stayed under sleep_speed for solver.sleep_time seconds (and no
// particle's substep motion exceeded 100 x sleep_speed x substep, so a vibration cannot hide between
// checks), the cloth falls asleep: its motion is set to zero and substeps only advance the clock. Any change
// of the settings (a collider moved, wind, a slider), a pin set or moved, a grab, or set_particle() wakes
// it, and it restarts from rest.
#pragma once

#include "clothsim/cloth_surface.hpp"
#include "clothsim/particle.hpp"
#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"
#include "clothsim/step_plan.hpp"
#include "clothsim/step_profile.hpp"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace clothsim {

struct Energy {
    double kinetic = 0.0;            // J: sum of m v^2 / 2 with second-order velocities
    double spring_potential = 0.0;   // J: k w (|d| - L0)^2 / 2 over springs, k w |x_a - 2 x_m + x_b|^2 / 2 over bends
    double gravity_potential = 0.0;  // J: -sum of m g . x over free particles
    double contact_potential = 0.0;  // J: sum of k_c p^4 / (4 t^2) over contacts (penalty contact; else 0)
    double potential() const { return spring_potential + gravity_potential + contact_potential; }
    double total() const { return kinetic + potential(); }
};

struct CollisionBlocks;
struct MotionBounds;
enum class BlockBounds;

class MassSpring {
public:
    // `state.position` holds the start positions; `initial_velocity` (one per particle, or empty for rest)
    // sets the start velocities. Previous positions are derived from them (second-order start).
    MassSpring(Topology topology, State state, SimulationSettings settings,
               const std::vector<glm::vec3>& initial_velocity = {});
    ~MassSpring();
    MassSpring(const MassSpring& other);
    MassSpring& operator=(const MassSpring& other);
    MassSpring(MassSpring&&) noexcept;
    MassSpring& operator=(MassSpring&&) noexcept;

    // One integration substep of length substep_length(): the whole pipeline, stage by stage.
    void substep();
    // `steps` whole steps of settings().integration.dt, each made of `substeps` substeps.
    void run_steps(long long steps);

    double substep_length() const;  // s: dt / substeps

    const SimulationSettings& settings() const { return settings_; }
    // The colliders where they are now: the settings' list, with each moving one (collider_motion.hpp) posed at
    // the simulation's time. What the renderer draws and the contact meets.
    const std::vector<Collider>& colliders() const;
    // Drags collider i (the app's alt+drag): from where it is now it moves in a straight line to `to` (its
    // centre; a mesh: its position), arriving `seconds` of simulated time from now, and stops there; the
    // contact meets it with that velocity, so the cloth it touches is pushed and carried by friction. Its
    // spin goes on. With seconds <= 0 it is put at `to` at rest (the end of a drag, or a move while paused).
    // Returns false (and changes nothing) when there is no collider i or `to` is not finite.
    bool move_collider(std::size_t i, glm::vec3 to, double seconds);
    // The one way to change the live settings: takes effect at the next substep. A change replans the stages
    // (step_plan.hpp), wakes the cloth (a moved collider, wind or a slider drives it) and moves
    // setup_stamp(); applying the settings already in force does nothing.
    void apply(const SimulationSettings& settings);
    // The same for integration.substeps alone (auto substeps, the guard).
    void set_substeps(int substeps);
    const Topology& topology() const { return topology_; }
    const State& state() const { return state_; }

    std::size_t particle_count() const { return state_.size(); }
    std::size_t spring_count() const { return topology_.springs.size(); }
    std::size_t bend_count() const { return topology_.bends.size(); }
    double time() const { return state_.time; }
    float rest_area() const { return rest_area_; }

    Particle particle(std::size_t i) const;
    // Positions rounded to float, as the renderer and exports use them; state() has them in double.
    glm::vec3 position(std::size_t i) const { return glm::vec3(state_.position.get(i)); }
    std::vector<glm::vec3> positions() const;
    // The same into `out`, resized to the particle count: a caller that keeps `out` (the renderer, each
    // frame) reuses its memory instead of allocating and zero-filling a new array.
    void positions(std::vector<glm::vec3>& out) const;
    // Second-order velocity estimates at the current positions (m/s), rounded to float.
    std::vector<glm::vec3> velocities() const;
    Energy energy() const;
    glm::vec3 momentum() const;  // kg m/s, free particles
    bool all_finite() const;
    // Whether settings().solver.method == Fast can run the fast solver (it needs a grid topology; it
    // runs position Verlet), and with how many threads the current settings step.
    bool fast_solver_available() const;
    int solver_threads() const;
    // A mesh cloth on the fast method: its springs and hinges, integration and tethers run on the work team, on
    // this many threads (0: not on the team).
    int mesh_team_threads() const;
    // Whether the last substep ran on the fast path: the fast solver (Verlet on a grid cloth) or the element
    // gather (element_gather.hpp: Verlet on a mesh cloth), or XPBD's grid form (grid_xpbd.hpp: xpbd with
    // solver.method = "fast" on a grid cloth) or its coloured form (coloured_xpbd.hpp: the same on a mesh cloth).
    bool last_step_fast() const;
    // Tethers to the pins (tethers.hpp; they act when springs.tether_strain > 0), and how many were at their
    // limit in the last substep.
    std::size_t tether_count() const;
    std::size_t tethers_at_limit() const { return tethers_at_limit_; }
    // Springs (and bends) broken by tearing since the cloth was built (springs.tear_strain; tearing.hpp).
    std::size_t broken_springs() const { return broken_springs_; }
    // m: the cloth's particle spacing as built, the least distance self-collision keeps (self_collision.hpp).
    double self_collision_spacing() const { return spacing_; }
    // Changes whenever the springs or triangles change (a tear), so a renderer rebuilds its mesh.
    std::uint64_t topology_stamp() const { return topology_stamp_; }
    // The surface to draw and export: split along the tears once the cloth has torn (cloth_surface.hpp), made
    // anew whenever the topology changes.
    const ClothSurface& surface() const { return surface_; }
    // How far the last substep's solve got (0 for the explicit integrators): implicit Euler's CG iterations and
    // |b - A dv| / |b|; projective's quasi-Newton iterations and relative force imbalance (projective.hpp);
    // XPBD's one iteration and its constraint residual |C + alpha~ lambda| / |C| at the current positions.
    int last_solver_iterations() const { return last_iterations_; }
    double last_solver_residual() const;
    // The fast solver's kernels on this CPU (chosen at run time): "avx512", "avx2+fma" or "generic".
    static const char* fast_kernel_name();
    // Runs the fast solver's (and grid XPBD's) kernels of `name` ("avx512", "avx2+fma" or "avx2", "generic")
    // from now on, for benchmarks that compare them on one machine; false, changing nothing, when the name is
    // unknown or this CPU lacks the instructions. Not thread-safe: call it before any simulation steps.
    static bool use_fast_kernel(const std::string& name);

    // The stages the current settings run.
    const StepPlan& plan() const { return plan_; }
    // Time per stage since the last reset_profile(); set_profiling(false) stops timing (and its clock reads).
    const StepProfile& profile() const { return profile_; }
    void reset_profile() { profile_ = StepProfile{}; }
    void set_profiling(bool on) { profiling_ = on; }

    // Asleep: the next step will not move anything (every change that could move the cloth wakes it).
    bool asleep() const;
    // s: how long the cloth has stayed under sleep_speed (it sleeps at solver.sleep_time).
    double calm_seconds() const;
    // Wakes a sleeping cloth (from rest) and restarts the count towards sleep.
    void wake();
    // Stops every particle where it is: zero velocity, positions unchanged (a settle's kinetic damping,
    // settle.hpp). A multistep integrator starts afresh.
    void stop();
    // 1/s of velocity damping added to springs.damping: a settle's own viscous damping once its fall is over
    // (settle.hpp), not a scene setting (the panel and the scene file never see it); 0 unless a settle runs.
    // Throws std::invalid_argument for a negative or non-finite rate.
    void set_settle_damping(double rate);
    double settle_damping() const { return settle_damping_; }
    // 1/s: the damping rate c in x'' = a - c x' that every integrator uses, springs.damping plus the settle's.
    double damping_rate() const { return settings_.springs.damping + settle_damping_; }
    // Changes whenever positions may have changed (a step, a pin moved, a rebuild); equal stamps mean equal
    // positions, even across copies (a rollback), so a renderer can skip normals and uploads.
    std::uint64_t change_stamp() const { return stamp_; }
    // Changes whenever what the stability limit depends on may have changed (the settings, a pin), so a
    // caller can keep a limit until then.
    std::uint64_t setup_stamp() const { return setup_stamp_; }

    // Sets every particle's mass (kg) in place, keeping positions and velocities (a material's density or
    // cloth.mass changed live): pinned particles keep inverse mass 0, absent ones mass 0. Throws
    // std::invalid_argument when `mass` has another length or a present particle's mass is not positive and
    // finite (nothing changes then).
    void set_masses(std::span<const float> mass);
    // Sets the weight of every spring (its k is the settings' k times its weight) to that of the spring with the
    // same two particles in `from`, in place (a mesh cloth's fabric changed live: cloth_mesh.hpp, membrane_springs;
    // a torn cloth has fewer springs than `from`). Throws std::invalid_argument, changing nothing, when a spring has
    // no match in `from` or would get a weight that is negative or not finite.
    void set_spring_weights(std::span<const Spring> from);
    // Pins or frees a particle; a newly pinned particle stops where it is.
    void set_pinned(std::size_t i, bool pinned);
    // Moves a pinned particle to `position` (a grab, a moving anchor); it carries no velocity of its own, its
    // springs pull on its neighbours from the new place at the next step. Does nothing to a free particle.
    void move_pinned(std::size_t i, glm::vec3 position);
    // A user's drag of pinned particle `i` toward `target`: the pin travels there at a steady speed over the
    // next step (the mouse's speed: the distance over integration.dt), a part of it each substep, and never
    // faster than kPinStepPerSubstep of the cloth's particle spacing per substep, the speed an explicit solver
    // follows (the Courant-Friedrichs-Lewy condition: a disturbance crosses at most one spacing per substep).
    // So a drag moves the pin smoothly whatever the frame rate, instead of one jump a frame. The pin goes no
    // farther from any other pin than (1 + tether_strain) times their rest distance while tethers act (the
    // tethers could not all hold beyond), else (1 + kPinDragStretch) times: the cloth between two pins holds
    // the pin there, as a real cloth would, instead of its few springs stretching without end (which the
    // guard takes for a blow-up). The pin keeps going until it reaches the target (or that limit); calling
    // again moves the target. Wakes the cloth. Does nothing to a free particle; freeing the pin drops its
    // target.
    void drag_pin(std::size_t i, glm::vec3 target);
    static constexpr double kPinStepPerSubstep = 0.25;
    static constexpr double kPinDragStretch = 0.5;
    // Where a dragged pin is heading (nothing when it is not dragged or has arrived).
    std::optional<glm::vec3> pin_target(std::size_t i) const;
    // A user's grab: free particle `i` is pulled toward `target` by a stiff, critically damped spring whose
    // force is capped (grab_force_limit), the way cloth follows the mouse in Blender or Ten Minute Physics,
    // instead of being teleported. Its stiffness is a quarter of m / h^2 (w h = 0.5 for the particle alone,
    // inside every explicit integrator's limit), the cap stretches the particle's own springs by 50% at most
    // (with a floor of 10 m |g|), so a hard drag pulls the cloth but cannot tear it into a spike. Calling it
    // again moves the target; it wakes the cloth. A pinned particle is moved with move_pinned instead.
    void grab(std::size_t i, glm::vec3 target);
    void release_grab();
    std::optional<std::size_t> grabbed() const;
    // N: the grab's force on the grabbed particle at the current state (0 without a grab), and its cap.
    glm::vec3 grab_force() const;
    float grab_force_limit() const;
    // A cut (the app's shift + right-drag): breaks every spring for which crosses(position a, position b) is
    // true, with the bends, bending springs and triangles that bridge it, as a tear does (tearing.hpp), and
    // wakes the cloth. Returns how many springs (bends included) broke.
    std::size_t cut(const std::function<bool(glm::vec3, glm::vec3)>& crosses);
    // Moves a particle and gives it a velocity (for tests and tools); others keep theirs.
    void set_particle(std::size_t i, glm::vec3 position, glm::vec3 velocity);

private:
    // Restarts Verlet from velocities at the current positions with substep h (used at construction and
    // when the substep length changes, so a new dt does not turn into a velocity jump).
    void restart(const std::vector<glm::dvec3>& velocity, double h);
    // velocities() in double, for restarts and the energy.
    std::vector<glm::dvec3> velocities_in_double() const;
    void compute_forces(const State& state, Vec3Array& force) const;
    // Wind, penalty contact and (with `holds`) soft clips' holds, as the plan has them, summed on their own into
    // `scratch` and then added to `force` (the fast solver adds them as one external force: both round alike);
    // timed when `profile` is set.
    void add_external_forces(const State& state, Vec3Array& force, Vec3Array& scratch, StepProfile* profile,
                             bool holds = true) const;
    void replan();
    void track_collider_motion();
    // Moves the particles that a mesh collider jumping onto the cloth swallowed out of it (colliders.hpp:
    // push_out_of_mesh): each enabled mesh that is new, or whose pose moved by 1% of the thickness or more from
    // `before`'s at the same index, or turned, or changed its mesh or scale.
    void push_out_of_jumped_meshes(const std::vector<Collider>& before);
    void pose_colliders(double t0, double t1) const;
    const ColliderSettings& colliders_now() const;
    // The stages of substep(), in pipeline order.
    void step_fast(double h, StepProfile* profile);
    void step_textbook(double h, StepProfile* profile);
    // `continues`: the state is what the previous substep left (a multistep integrator may use its history).
    void step_velocity_integrator(Integrator integrator, double h, bool continues);
    // Returns false when it moved no particle. `motion`: the bounds of every particle's motion as it is now, or
    // null (collide_stage).
    bool collide(StepProfile* profile, const MotionBounds* motion = nullptr);
    // Whether the fast solver's sweep takes the bounds of the motion it writes: for self-collision, and for the
    // swept boxes of the sphere, the cube and the cylinder (collide_stage).
    bool sweep_takes_motion_bounds() const;
    // `known`: the bounds of the motion as it is now, or null. Returns whether it moved anything.
    bool collide_self(StepProfile* profile, const MotionBounds* known, bool uncounted);
    // Returns how many tethers were at their limit. With `boxes`, each band of the fast solver also boxes its
    // rows for the broad phase, bounded as `*boxes` says, right after projecting them (one job, not two).
    std::size_t apply_tethers(const BlockBounds* boxes = nullptr);
    // Whether the collision blocks are boxed on the fast solver's bands after the stages that follow the solver
    // moved particles (else the collision stage boxes them).
    bool boxes_on_team() const;
    // The collision blocks' boxes again after the stages that follow the solver moved particles; false when
    // left to the collision stage. `made`: the bounds the boxes were already made with (by apply_tethers),
    // kept when the bounds are still the same.
    bool box_blocks_on_team(StepProfile* profile, const BlockBounds* made = nullptr);
    // Sizes the collision blocks' boxes for the grid and records the bounds box_rows makes them with.
    void start_boxes(BlockBounds bounds);
    // Boxes rows [begin, end) of the collision blocks (the fast solver's grid layout).
    void box_rows(int band, int begin, int end, BlockBounds bounds);
    // Each returns whether it moved a particle.
    bool limit_strain();
    bool limit_speed(double h);
    void tear();
    // After springs broke: everything that follows the topology, at the point of change.
    void topology_changed(std::size_t removed);
    void rebuild_tethers();
    void build_fast_solver();
    glm::vec3 grab_force(const State& state) const;
    // N: the grab's force cap for particle i at the current masses and stiffness (grab()).
    float grab_force_limit(std::size_t i) const;
    // The first stage of a substep: dragged pins step toward their targets (drag_pin). Returns whether any moved.
    bool move_dragged_pins();
    // Where pin i may go on its way to `x`, within reach of the other pins (drag_pin).
    glm::dvec3 within_reach_of_pins(std::size_t i, glm::dvec3 from, glm::dvec3 x) const;

    // Everything else the simulation keeps (src/core/simulation/mass_spring_internals.hpp): the solvers' caches,
    // the collision blocks, self-collision, tethers, the grab, dragged pins, the sleep monitor. Held by a
    // pointer that copies what it points to, so a copy of the simulation carries all of it.
    struct Internals;
    class InternalsPtr {
    public:
        InternalsPtr();
        InternalsPtr(const InternalsPtr& other);
        InternalsPtr& operator=(const InternalsPtr& other);
        InternalsPtr(InternalsPtr&&) noexcept;
        InternalsPtr& operator=(InternalsPtr&&) noexcept;
        ~InternalsPtr();
        Internals* operator->() const { return p_.get(); }
        Internals& operator*() const { return *p_; }
    private:
        std::unique_ptr<Internals> p_;
    };
    friend const CollisionBlocks& collision_blocks(const MassSpring& sim);

    Topology topology_;
    InternalsPtr in_;
    State state_;
    SimulationSettings settings_;
    std::uint64_t history_stamp_ = 0;  // stamp_ as the last substep left it; 0 after a restart
    double settle_damping_ = 0.0;      // 1/s, set_settle_damping
    std::size_t broken_springs_ = 0;
    std::uint64_t topology_stamp_ = 0;
    ClothSurface surface_;       // follows topology_ (topology_changed)
    ClothCells cells_at_start_;  // the cells a tear can leave torn, as built (cloth_surface.hpp)
    StepPlan plan_;
    StepProfile profile_;
    bool profiling_ = true;
    Vec3Array force_;            // N, scratch of the current substep
    Vec3Array external_;         // N, scratch: wind and contact summed on their own before they are added
    float rest_area_ = 0.0f;     // m^2: sum of the triangles' rest areas
    double spacing_ = 0.0;       // m: particle_spacing() of the cloth as built
    DVec3Array rest_position_;   // m: the positions the cloth was built with (flat, at rest)
    std::size_t tethers_at_limit_ = 0;
    int last_iterations_ = 0;
    double last_residual_ = 0.0;
    int substeps_since_check_ = 0;
    std::uint64_t stamp_ = 0;
    std::uint64_t setup_stamp_ = 0;
    Vec3Array grab_external_;    // N: the grab's and soft clips' forces (zero elsewhere), for the fast solver
};

// The box around the cloth's finite particles, the enabled sphere, cube and cylinder, and down to the ground
// when it is enabled (where a falling cloth ends up): what the camera frames and the shadow map covers. An
// empty or all-NaN cloth gives the box at the origin (and the ground).
void scene_bounds(const MassSpring& sim, glm::vec3& lo, glm::vec3& hi);

}  // namespace clothsim
