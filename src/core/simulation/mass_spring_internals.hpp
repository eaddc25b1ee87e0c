// What MassSpring keeps that is not its API: the fast solver, the iterative integrators' caches, the collision
// broad phase's blocks, self-collision, the tethers, the grab, dragged pins and the sleep monitor. It lives
// here, in src/core, so include/clothsim/mass_spring.hpp needs none of their headers; MassSpring holds it by
// a pointer that copies it whole (a copy of the simulation is a rollback point: it carries all of this).
#pragma once

#include "clothsim/mass_spring.hpp"

#include "collision/colliders.hpp"
#include "collision/self_collision.hpp"
#include "integrators/fast_solver.hpp"
#include "integrators/integrator_step.hpp"
#include "model/element_gather.hpp"
#include "model/grab_spring.hpp"
#include "model/tethers.hpp"
#include "simulation/sleep_monitor.hpp"

#include <optional>
#include <vector>

namespace clothsim {

struct MassSpring::Internals {
    // A pin on its way to a target (drag_pin).
    struct PinTarget {
        std::size_t particle = 0;
        glm::dvec3 target{0.0};  // m
        double reach = 0.0;      // m per substep
    };

    std::optional<FastSolver> fast;    // when the topology is a grid
    std::optional<ElementGather> gather;  // when it is a mesh cloth: its springs and hinges on the team
    std::vector<std::size_t> tether_pieces;  // a mesh cloth's tethers at their limit, per piece of the team's job
    IntegratorCaches iterative;        // projective's factorisation and BDF2 history, XPBD's multipliers and grid form
    CollisionBlocks blocks;            // particle blocks and their boxes for the collision broad phase
    MotionBounds motion_bounds;        // the fast solver's bounds of this substep's motion (sweep_takes_motion_bounds)
    Tethers tethers;                   // to the current pins, rebuilt when a pin is set or freed
    std::optional<SelfCollision> self_collision;  // built when collision.self is first on
    bool moved_uncounted = false;      // the last substep moved particles after its self stage, outside their motion
    SleepMonitor sleep;
    std::optional<GrabSpring> grab;
    std::vector<PinTarget> pin_targets;  // pins dragged toward a target (drag_pin), at most a few
    // Kinematic colliders (collider_motion.hpp): while one of the settings' colliders moves, `posed` holds the
    // list posed at `posed_time` and `surfaces` each one's surface motion over the substep ending then.
    bool colliders_move = false;
    ColliderSettings posed;
    double posed_time = 0.0;
    std::vector<SurfaceMotion> surfaces;


    // The stiffness, the substep, the pins or the topology changed: the projective solver factorises again and
    // XPBD's grid form is made again, at the next substep that uses them.
    void invalidate_iterative();
};

// The collision broad phase's blocks and their boxes as the last substep left them (for tests).
const CollisionBlocks& collision_blocks(const MassSpring& sim);

}  // namespace clothsim
