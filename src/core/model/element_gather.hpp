// The spring, hinge and membrane forces of a cloth on a team of threads, as a gather: each element's force is computed
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

#include <array>
#include <cstdint>
#include <vector>

namespace clothsim {

struct ElementGather {
    // Particle i's terms are [begin[i], begin[i + 1]): it adds coefficient[k] * element_force[source[k]] for
    // each k, in list order. element_force holds the springs' forces on their end a (j) and then the hinges'
    // e = k sum_i c_i x_i (springs + h), then each membrane's p_u and p_v (membrane.hpp; springs + hinges + 2 m
    // and the next); a spring's coefficient is +1 at end a and -1 at end b (exact: the product is the force or
    // its negation), a hinge's is -c_slot, a membrane's bu_i on p_u and bv_i on p_v.
    std::vector<std::uint32_t> begin, source;
    std::vector<float> coefficient;
    // Then each rim corner's forces on its a, p and q (gaussian_curvature.hpp; coefficient 1).
    std::size_t springs = 0, hinges = 0, membranes = 0, corners = 0;
    Vec3Array element_force;
    // The elements as the AVX-512 element pass reads them, in list order: a spring's ends, rest length, weight
    // and which stiffness of the settings it takes (0 structural u, 1 structural v, 2 shear, 3 bending u, 4
    // bending v); a hinge's four particles, weights c_1..c_3 (c_0 multiplies no difference) and bending
    // weights. set_weights copies the springs' weights again after MassSpring::set_spring_weights.
    std::vector<std::int32_t> spring_a, spring_b, spring_stiffness;
    std::vector<float> spring_rest, spring_weight;
    std::array<std::vector<std::int32_t>, 4> hinge_v;
    std::array<std::vector<float>, 3> hinge_c;
    std::vector<float> hinge_weight_u, hinge_weight_v;
    // A membrane's three particles, its weights bu_1, bu_2, bv_1, bv_2 (bu_0 and bv_0 multiply no difference) and
    // rest area.
    std::array<std::vector<std::int32_t>, 3> membrane_v;
    std::array<std::vector<float>, 4> membrane_b;
    std::vector<float> membrane_area;
    // The same terms for the AVX-512 sum, sixteen particles a block, one lane each: block b's term t of lane l
    // is at lanes_begin[b] + 16 t + l, for t below the lane's count (lane_terms); the rest are padding.
    std::vector<std::uint32_t> lanes_begin, lane_source, lane_terms;
    std::vector<float> lane_coefficient;

    // For `topology`'s springs and hinges (bends are the grid's: none on a mesh cloth; a topology with bends
    // gets none). Build again when the topology changes (a tear).
    static ElementGather for_topology(const Topology& topology);
    void set_weights(const Topology& topology);
};

// Adds the springs' and hinges' forces to `force` (each particle's to what it holds, in the list path's order),
// on at most `threads` threads of the shared WorkTeam. The topology has no bends (a mesh cloth's).
void gather_spring_forces(const Topology& topology, ElementGather& gather, const DVec3Array& position,
                          const SpringSettings& springs, Vec3Array& force, int threads);

}  // namespace clothsim
