// Collision with the scene's list of shapes (collider.hpp: spheres, boxes, cylinders, planes): the projection
// contact model (colliders.contact = projection, the default; penalty_contact.hpp in src/core has the smooth
// force model).
//
// After integration every free particle closer than `thickness` to a collider surface is projected out
// to that distance along the surface normal (a box and a cylinder: along the shortest way out). The
// contact is inelastic: the inward part of the substep's motion is removed, and the push itself adds no
// velocity. Friction acts on the tangential motion like Coulomb friction in position-based dynamics (Mueller
// et al. 2007, Macklin et al. 2014): it is reduced by at most mu times the normal correction, and stops
// when it is smaller (static friction). A particle resting on a plane is pushed
// back by g h^2 each substep, so its sliding velocity drops by mu g h per substep: deceleration mu g.
//
// Continuous collision: a particle whose path over the substep (x - motion -> x) went through a solid shape,
// though it ends outside (or inside, past the middle), is stopped where the path entered the thickness shell,
// its inward motion removed. A plane is a half-space and needs no sweep.
#pragma once

#include "collision/broad_phase.hpp"
#include "clothsim/collider_motion.hpp"
#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"
#include "clothsim/step_profile.hpp"

#include <glm/vec3.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include <vector>

namespace clothsim {

// Collision of particles [begin, end) (all by default) with one collider, enabled or not. Pinned particles
// are never moved.
inline constexpr std::size_t kAllParticles = static_cast<std::size_t>(-1);
void collide(State& state, const Collider& collider, float thickness, std::size_t begin = 0,
             std::size_t end = kAllParticles);
// Every enabled collider, in the list's order, testing every particle (the reference solution).
void collide_all(State& state, const ColliderSettings& colliders, std::size_t begin = 0,
                 std::size_t end = kAllParticles);

// A collider that jumps onto the cloth (a typed position, a dropped mesh, a cloth built inside it) may swallow
// particles deeper than its thickness shell. The analytic solids push those out from any depth at the next
// substep; a mesh's contact sees only its shell (shapes/mesh.hpp), so this moves each free particle deeper
// inside a closed mesh than the thickness out by the nearest way, to the thickness outside the surface,
// keeping its motion less any part into the surface (an inelastic contact). Open meshes have no inside and
// other shapes need none: nothing is moved. Returns how many particles moved.
std::size_t push_out_of_mesh(State& state, const Collider& collider, float thickness);

// The particles as blocks (broad_phase.hpp: block_starts), each block's box and the whole cloth's box.
//
// The carried box holds every particle, and the start of its path over the substep (x - motion, where the
// swept tests begin), from substep to substep without a pass over them: a substep's sweep moves each particle
// by its motion, so the box grown by the motion's bounds (and by zero: it keeps where the particles started)
// holds them after it. A tether keeps its particle in it (it moves the particle toward its pin) and moves its
// path's start by at most its motion, which the box grows by (MassSpring::step); any other move (a collider's
// push, a limit, self-collision, an edit) and any substep without a solid shape make it invalid until the
// next whole boxes. While it lies out of reach of the solid shapes, the blocks need only their lowest points
// (for the planes) and each solid shape costs one test.
struct CollisionBlocks {
    std::vector<std::size_t> start;  // block k is particles [start[k], start[k + 1])
    std::vector<Box> boxes;          // one per block
    BlockBounds bounds = BlockBounds::Box;  // what `boxes` hold
    Box cloth;                       // contains every block's box
    // The union of the boxes each band of the fast solver's rows made (its sweep, or box_rows in the tethers'
    // job, on that band's thread while they are in its cache), valid while `band_unions`: the collision stage
    // then takes `cloth` from these 64 instead of reading every block's box, half of them from the other core's
    // cache (1.5 us a substep at 128 x 128 on two threads). The stage clears it once used.
    static constexpr std::size_t kBandUnions = 64;
    std::array<Box, kBandUnions> band_union{};
    bool band_unions = false;
    bool boxes_current = false;      // the block boxes bound the particles as they are now (the fast solver's)
    bool current = false;            // ... and `cloth` bounds them
    glm::dvec3 carried_lo{0.0}, carried_hi{0.0};  // the carried box (above), in double: it grows every substep
    bool carried_valid = false;
    Box carried() const { return Box{glm::vec3(carried_lo), glm::vec3(carried_hi)}; }
    // The particles are about to move (a substep begins): the last substep's boxes no longer bound them.
    void positions_moving() { current = boxes_current = false; }
    // A move the carried box does not follow (an edit, a dragged pin, a push, a limit): it is made again from
    // the next whole boxes.
    void moved_outside_motion() { carried_valid = false; }
    // Grows the carried box by `by` on every side; drops it when `by` is not a number that bounds anything.
    void widen_carried(double by) {
        carried_valid = carried_valid && std::isfinite(by);
        carried_lo -= glm::dvec3(by);
        carried_hi += glm::dvec3(by);
    }
    // Scratch of collide_stage: the blocks a collider tests, and which of them its pushes grew.
    std::vector<std::uint32_t> tested;
    std::vector<std::uint8_t> grown;
    std::size_t count() const { return start.empty() ? 0 : start.size() - 1; }
};

// The collision stage of a substep: the same contacts as collide_all, in the same order, but with
// `broad_phase` a collider is skipped when it cannot touch the whole cloth's box, and is otherwise tested
// particle by particle only on the blocks whose box may touch it (broad_phase.hpp). The boxes are computed
// here unless the fast solver left them (boxes_current), and a block's box is grown by the farthest push a
// collider gave one of its particles, so the next collider's test stays conservative.
// Each collider's time and block counts go to `profile` when it is not null. `threads` share the blocks a
// collider tests when they hold kParallelCollisionParticles particles or more (four times as many for a
// plane; the same result for any count). Returns false when no particle was tested against any collider, so
// none moved. `motion`, when not null, bounds every particle's motion as it is now (the fast solver's sweep
// takes them while it writes the motions): the swept boxes' reach then costs no pass over the motions.
//
// With Lowest boxes from the caller and a solid shape enabled, the solid shapes test the carried box, grown
// here by `motion` (null: the caller has kept it since the sweep); when it may reach one of them, or cannot
// be grown (bounds that are not finite), the stage makes whole boxes itself.
inline constexpr std::size_t kParallelCollisionParticles = 1024;
//
// `surfaces`, when not null, holds one SurfaceMotion per collider (collider_motion.hpp): a collider whose
// motion moves is met with the particles' motion relative to its surface, its shape already posed at the
// substep's end by the caller.
bool collide_stage(State& state, const ColliderSettings& colliders, bool broad_phase, CollisionBlocks& blocks,
                   StepProfile* profile, int threads = 1, const MotionBounds* motion = nullptr,
                   const SurfaceMotion* surfaces = nullptr);

// What the fast solver's sweep should compute of each block for the next substep's collision stage: Lowest
// when planes are the only colliders, or when the carried box is valid and out of reach of every solid shape;
// whole boxes otherwise.
BlockBounds block_bounds_for(const ColliderSettings& colliders, const CollisionBlocks& blocks);

}  // namespace clothsim
