// Self-collision: a cloth whose layers never pass through each other (collision.self).
//
// The model (Bridson, Fedkiw & Anderson 2002 for a thickness kept between layers; Müller's Ten Minute
// Physics tutorial 15, "self-collision", for the particle form and its hash):
//  - Every particle is a ball of diameter d, the contact distance: collision.self_thickness, raised to the
//    cloth's particle spacing s when it is smaller. Two particles that share no spring and come closer
//    than min(d, their rest distance) are pushed apart to it, each by its share of the inverse mass; their
//    approach along the line between them is removed from their motion (an inelastic contact) and their
//    sliding is slowed by Coulomb friction (collision.self_friction), both without changing the momentum.
//  - Why d >= s keeps layers from crossing: the balls of a flat layer then cover a slab of half-thickness
//    sqrt(d^2 - s^2 / 2) >= s / sqrt(2) around it, so a particle of another layer that keeps out of every
//    ball stays on its side, and a triangle of that layer cannot straddle the slab unless an edge of
//    length s or s sqrt(2) is stretched by 41% (docs/SELF_COLLISION.md).
//  - Why it cannot tunnel: no particle moves more than d / 4 in a substep (its motion is clamped, as Ten
//    Minute Physics clamps velocity), so two layers close by at most d / 2 between two checks, less than
//    the slab they must cross.
//
// Broad phase: the grid is cut into tiles of kSelfTile x kSelfTile particles. Each substep boxes every tile
// and sweeps the boxes along x (kept sorted from substep to substep, so the sort is nearly free); when no
// two tiles that are not grid neighbours come within d, and no tile or pair of neighbouring tiles is
// folded (its box diagonal under 0.9 of its rest diagonal), nothing else runs (tested with a reach of
// d + (kSelfSkip - 1) d / 2, an empty test also covers the next kSelfSkip - 1 substeps, since no particle
// moves more than d / 4 a substep: the stage then costs the motion clamp alone). Otherwise the narrow phase
// tests every particle pair of those tile pairs, and of each such tile with itself and its grid
// neighbours (where a fold between far tiles turns). The pairs within d are resolved in index order
// (Gauss-Seidel, one pass a substep), so the result does not depend on the order the tiles came in.
#pragma once

#include "clothsim/broad_phase.hpp"
#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace clothsim {

inline constexpr int kSelfTile = 4;  // particles along each side of a broad-phase tile
inline constexpr int kSelfSkip = 4;  // substeps one box test that finds nothing covers

// The cloth's particle spacing: its longest structural rest length (0 without structural springs).
double particle_spacing(const Topology& topology);

// What one substep of the stage did, for the profile.
struct SelfCollisionCounts {
    long long tiles = 0;         // tiles boxed
    long long tiles_active = 0;  // tiles sent to the narrow phase (0: skipped after the box test)
    long long contacts = 0;      // pairs pushed apart
    long long clamped = 0;       // particles whose motion was clamped to d / 4
};

class SelfCollision {
public:
    SelfCollision() = default;
    // The tiles, each particle's spring neighbours and the particle spacing, from the cloth as built.
    SelfCollision(const Topology& topology, const DVec3Array& rest_position);
    // After a tear: the neighbours follow the springs that are left (the spacing stays the built cloth's).
    void update_neighbours(const Topology& topology);

    // The contact distance d for these settings: max(self_thickness, spacing).
    double contact_distance(const CollisionSettings& settings) const;
    double spacing() const { return spacing_; }

    // One substep of the stage on `state` (after integration and the colliders). Returns what it did;
    // positions or motions changed when contacts or clamped is not 0.
    SelfCollisionCounts collide(State& state, const CollisionSettings& settings, const DVec3Array& rest_position);

    // Whether particles i and j share a spring or a bend (then they never collide).
    bool neighbours(std::uint32_t i, std::uint32_t j) const;

private:
    int tile_rows_ = 0, tile_cols_ = 0;     // tiles of the grid (rows x cols), or one row of runs
    bool grid_ = false;                     // false: tiles are runs of kSelfTile^2 particles along the list
    int rows_ = 0, cols_ = 0;
    std::size_t particles_ = 0;
    double spacing_ = 0.0;                  // m: the longest structural rest length
    std::vector<std::uint32_t> neighbour_begin_, neighbour_;  // sorted spring neighbours of each particle
    // Scratch, kept between substeps.
    std::vector<Box> boxes_;
    std::vector<std::uint32_t> order_;      // tiles sorted by box.lo.x (the last substep's order)
    std::vector<std::uint8_t> active_;      // tiles within d of a tile that is not a grid neighbour
    std::vector<std::uint64_t> tile_pairs_; // (a << 32 | b), a <= b: the tile pairs the narrow phase tests
    std::vector<std::uint64_t> candidates_; // (i << 32 | j), i < j: particle pairs within d
    std::vector<std::uint32_t> first_, second_;
    std::vector<int> tile_row_, tile_col_;  // each tile's place in the grid of tiles
    std::vector<float> tile_rest_;          // per tile: rest diagonals of it alone and with 4 neighbours
    float d_for_reach_ = 0.0f;              // the d of the current box test
    int substeps_to_test_ = 0;              // substeps the last empty box test still covers
    double tested_distance_ = 0.0;          // the d it was made for

    bool adjacent_tiles(std::uint32_t a, std::uint32_t b) const;
    void tile_boxes(const DVec3Array& position);
    // Marks the tiles that come within `reach` of a non-adjacent tile and lists the tile pairs to test: those, and
    // each marked tile with itself and its grid neighbours. Returns how many tiles are marked.
    std::size_t mark_active(float reach);
    void tile_particles(std::uint32_t t, const State& state, std::vector<std::uint32_t>& out) const;
};

}  // namespace clothsim
