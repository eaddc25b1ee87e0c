// Tethers: long-range attachments (Kim, Chentanez & Mueller 2012, "Long Range Attachments - A Method to
// Simulate Inextensible Clothing in Computer Games", SCA 2012).
//
// A stiff cloth hanging from pins stretches most next to them: every spring between a pin and the hem
// carries the weight below it, and a local solver needs many iterations (or substeps) to pass that load
// along a long chain. A tether ties a free particle straight to a pin with a unilateral constraint
//   |x - x_pin| <= (1 + springs.tether_strain) L,
// L the particle's rest distance from the pin. The cloth's rest shape is flat and convex (a rectangle or a
// disc), so L is also the geodesic distance, the shortest path within the cloth: an inextensible cloth can
// never be farther from a pin than that, so a tether changes nothing while the cloth stretches less than
// tether_strain along the way, and stops it stretching more. A particle next to a pin is tied at exactly
// its springs' rest length, so the springs at a pin stretch by tether_strain at most.
//
// Which pins: pinned particles joined by a spring form a cluster (a clip, a pinned row, one corner). Each
// free particle is tied to the nearest pinned particle of each of its kMaxTethersPerParticle nearest
// clusters (by rest distance). The tethers are built when the cloth is and again whenever a pin is set or
// freed (MassSpring::set_pinned); a pin moved by move_pinned keeps its tethers and they follow it.
#pragma once

#include "clothsim/state.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace clothsim {

inline constexpr int kMaxTethersPerParticle = 4;

// Structure of arrays, grouped by particle in index order, each particle's farthest pin first.
struct Tethers {
    std::vector<std::uint32_t> particle;  // the free particle
    std::vector<std::uint32_t> anchor;    // the pinned particle it is tied to
    std::vector<double> rest;             // m: their rest distance
    std::size_t size() const { return particle.size(); }
    bool empty() const { return particle.empty(); }
};

// The tethers of a cloth whose rest positions are `rest` (the flat sheet it was built as), pinned as
// `state.pinned` says.
Tethers build_tethers(const Topology& topology, const State& state, const DVec3Array& rest);

// Every particle farther than (1 + strain) L from an anchor is moved back onto that sphere, radially, and
// its motion away from the anchor is removed (the anchor is pinned and does not move): a tether at its
// limit stops the particle stretching it, and like a collision push it adds no velocity of its own, so it
// never adds energy. One pass in tether order; returns how many tethers were at their limit.
std::size_t project_tethers(State& state, const Tethers& tethers, double strain);
// The same for tethers [first, last) only. A tether moves only its own free particle, towards a pin that does
// not move, so particles' tethers may be projected in any order of particles (on several threads) with the
// same result, as long as each particle's run stays in order.
std::size_t project_tethers(State& state, const Tethers& tethers, double strain, std::size_t first, std::size_t last);
// The first tether of a particle at or after `particle` (tethers are grouped by particle in index order).
std::size_t first_tether_from(const Tethers& tethers, std::uint32_t particle);

}  // namespace clothsim
