// The spring and hinge forces of a cloth on a team of threads, as a gather: each element's force is computed
// once, in parallel over the elements (a spring's f_a, a hinge's k sum_i c_i x_i), then each particle sums the
// forces of its own elements, in parallel over the particles, from a compressed list of them by particle (CSR).
// Nothing is scattered, so no two threads write one particle.
//
// Each particle sums its elements in list order, springs before hinges, with the arithmetic of
// accumulate_spring_forces (forces.hpp), so the sum is the same float sequence, rounded the same way: the
// result is bit-identical to the list path's on any number of threads. A mesh cloth's Verlet takes it with
// solver.method = "fast" (the grid has its own fast solver).
#pragma once

#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include <cstdint>
#include <vector>

namespace clothsim {

struct ElementGather {
    // Particle i's elements are entry[begin[i] .. begin[i + 1]): element * 4 + slot, the element a spring
    // index j (slot 0: end a, slot 1: end b) or springs + a hinge index (slot: which of its four particles).
    std::vector<std::uint32_t> begin, entry;
    std::size_t springs = 0, hinges = 0;
    Vec3Array spring_force;  // per spring: the force on its end a (b gets minus it)
    Vec3Array hinge_force;   // per hinge: e = k sum_i c_i x_i (particle i gets -c_i e)

    // For `topology`'s springs and hinges (bends are the grid's: none on a mesh cloth; a topology with bends
    // gets none). Build again when the topology changes (a tear).
    static ElementGather for_topology(const Topology& topology);
};

// Adds the springs' and hinges' forces to `force` (each particle's to what it holds, in the list path's order),
// on at most `threads` threads of the shared WorkTeam. The topology has no bends (a mesh cloth's).
void gather_spring_forces(const Topology& topology, ElementGather& gather, const DVec3Array& position,
                          const SpringSettings& springs, Vec3Array& force, int threads);

}  // namespace clothsim
