// Self-collision: a cloth whose layers never pass through each other (collision.self).
//
// The model (Bridson, Fedkiw & Anderson 2002 for a thickness kept between layers; Müller's Ten Minute
// Physics tutorial 15, "self-collision", for the particle form and its hash):
//  - Every particle is a ball of diameter d, the contact distance: collision.self_thickness, raised to the
//    cloth's particle spacing s when it is smaller. Two particles that share no spring (strangers) and
//    come closer than min(d, their rest distance) are pushed apart to it, each by its share of the inverse
//    mass; their approach along the line between them is removed from their motion (an inelastic contact)
//    and their sliding is slowed by Coulomb friction (collision.self_friction), both without changing the
//    momentum.
//  - Fold pairs, the two ends of a skip-one bending spring or of a bend (2 s apart at rest), are kept
//    min(d, rest / 4) apart the same way. Without it a crease sharper than the grid turns inside out: the
//    particles on either side of the fold line pass each other, and triangles one or two rows apart cross
//    (docs/SELF_COLLISION.md has the counts). At s / 2 a fold pair keeps the angle at its middle particle
//    above about 29 degrees; at s (rest / 2) a cloth could not wrap a bar thinner than its spacing, and `fold`'s
//    slid off its bar. Particles a structural or shear spring joins never collide.
//  - Why d >= s keeps layers from crossing: the balls of a flat layer then cover a slab of half-thickness
//    sqrt(d^2 - s^2 / 2) >= s / sqrt(2) around it, so a particle of another layer that keeps out of every
//    ball stays on its side, and a triangle of that layer cannot straddle the slab unless an edge of
//    length s or s sqrt(2) is stretched by 41% (docs/SELF_COLLISION.md).
//  - Why it cannot tunnel: no particle moves more than d / 4 in a substep (its motion is clamped, as Ten
//    Minute Physics clamps velocity), so two layers close by at most d / 2 between two checks, less than
//    the slab they must cross.
//
// Broad phase: the grid is cut into tiles of kSelfTile x kSelfTile particles. Each test boxes every tile and
// sweeps the boxes along x (kept sorted from test to test, so the sort is nearly free). Two kinds of tile
// go to the narrow phase:
//  - far pairs: tiles that are not grid neighbours and come within d of each other (layers meeting);
//  - folded tiles, with themselves and their neighbours (a fold or buckle shorter than two tiles): a tile
//    whose vector area (the cross product of its corner diagonals) falls under half its rest value, two
//    neighbours whose mean normals point apart (more than 90 degrees: a hairpin; Volino &
//    Magnenat-Thalmann 1994's normal cone), or a tile alone or with a neighbour whose box diagonal falls
//    under 0.8 of its rest diagonal (a box's diagonal is at least the distance between any two of its
//    particles: an accordion buckle that leaves each tile's normal alone).
// Off the grid (a mesh cloth) the tiles are patches of up to 16 particles grown breadth-first over the links,
// neighbours when a link joins them; a patch's shape is the mesh's, so there is no fold test: every patch is
// tested with itself and its neighbours at every test, the sweep finds the far pairs, and a fold pair is
// listed out to its kept distance plus the whole skin (the skin is the budget).
// The narrow phase compares every particle of one tile with every particle of the other (16 x 16, four at
// a time in float), keeps the pairs that may touch (see the list below), and resolves them in index order
// in double (Gauss-Seidel, one pass a substep), so the result does not depend on the order of the tiles.
// Skipping (conservative advancement, as Mirtich 1996 and Tang et al. 2009 advance bodies by a bound on
// their approach): a test that finds nothing also measures the room left, the budget: the smallest gap
// between far tile boxes within d + kSelfLookAhead d, less d, and how far each fold threshold still is
// (a diagonal shrinks by at most as much as two particles close in; a vector area and a mean normal change
// by at most a bound per unit of that, to first order). Each substep then takes the spread of the motions,
// |max - min| over the particles per component, which bounds how much any two particles closed in, off the
// budget, and tests again only when it is spent. Moves that are not motions (a collider's push, a tether,
// the strain or speed limit, and the steps of RK4 and projective, whose motion is v h rather than the
// displacement) are not counted: substeps that had any are covered by a test at most kSelfSkipMax of them
// apart. And a test at least every kSelfSkipLimit substeps bounds what the fold thresholds' first-order
// estimates leave out. A cloth that falls or rests as a whole spends almost none of the budget; the stage
// then costs one vectorised pass over the motions (none when the sweep took them).
// A test that finds pairs near each other lists every particle pair within its kept distance + a skin,
// kSelfSkin d (at most half the kept distance for a fold pair): a Verlet neighbour list, as molecular
// dynamics keeps one. Until the particles closed in by the skin, or a fold threshold of the tiles not in
// the narrow phase is reached, no other pair can come within its kept distance, so the substeps between
// tests only resolve the listed pairs. Fold pairs are a threshold of their own: one within its kept
// distance plus its skin puts both its tiles in the narrow phase (a crease sharper than a tile). The pushes themselves move particles outside
// their motion, so what they moved comes off the budget too.
#pragma once

#include "collision/broad_phase.hpp"
#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include <cstddef>
#include <array>
#include <cstdlib>
#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

namespace clothsim {

inline constexpr int kSelfTile = 4;  // particles along each side of a broad-phase tile
inline constexpr int kSelfSkipMax = 64;           // substeps with uncounted moves one test covers at most
inline constexpr int kSelfSkipLimit = 1024;       // substeps one test covers at most
inline constexpr double kSelfLookAhead = 8.0;     // far gaps are measured out to d + kSelfLookAhead d
inline constexpr double kSelfSkin = 0.5;          // a test lists the pairs within d + kSelfSkin d
inline constexpr double kSelfFoldShare = 0.25;    // a fold pair keeps min(d, this x its rest distance)

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
    void update_neighbours(const Topology& topology, const DVec3Array& rest_position);

    // The contact distance d for these settings: max(self_thickness, spacing).
    double contact_distance(const CollisionSettings& settings) const;
    double spacing() const { return spacing_; }

    // One substep of the stage on `state` (after integration and the colliders). `known`, when not null, is
    // the bounds of state.motion as it is now (the fast solver's sweep leaves them); otherwise the stage reads
    // every motion once for them. `uncounted`: something besides the motions moved particles since the last
    // substep (see the skipping above). Returns what it did; positions or motions changed when contacts or
    // clamped is not 0.
    SelfCollisionCounts collide(State& state, const CollisionSettings& settings, const DVec3Array& rest_position,
                                const MotionBounds* known = nullptr, bool uncounted = true);
    // Something moved particles outside a step (an edit, a restart): the next substep tests afresh.
    void invalidate() { tested_distance_ = 0.0; }

    // The particle pairs (i << 32 | j, i < j) the last substep resolved from: every pair within its reach
    // (kept distance + skin) at the last test.
    const std::vector<std::uint64_t>& listed_pairs() const { return candidates_; }

    // Whether particles i and j share a spring or a bend.
    bool neighbours(std::uint32_t i, std::uint32_t j) const;
    // Whether i and j are a fold pair: the ends of a bending spring or a bend.
    bool fold_pair(std::uint32_t i, std::uint32_t j) const;
    // The least distance the stage keeps between particles i and j for contact distance d (rest: their
    // distance in `rest_position`): min(d, rest) for strangers, min(d, rest / 4) for a fold pair, 0 (none)
    // for other neighbours.
    double kept_distance(std::uint32_t i, std::uint32_t j, double d, const DVec3Array& rest_position) const;

private:
    struct TilePoints {
        float x[kSelfTile * kSelfTile], y[kSelfTile * kSelfTile], z[kSelfTile * kSelfTile];
        std::uint32_t index[kSelfTile * kSelfTile];
        int row[kSelfTile * kSelfTile], col[kSelfTile * kSelfTile];
        int count = 0;
    };

    int tile_rows_ = 0, tile_cols_ = 0;     // tiles of the grid (rows x cols), or one row of patches
    bool grid_ = false;                     // false: tiles are patches grown over the links (below)
    int rows_ = 0, cols_ = 0;
    std::size_t particles_ = 0;
    double spacing_ = 0.0;                  // m: the longest structural rest length
    std::vector<std::uint32_t> neighbour_begin_, neighbour_;  // sorted spring neighbours of each particle
    std::vector<double> neighbour_fold_kept_;  // per entry of neighbour_: its fold pair's kept rest, else 0
    // Off the grid: -1 for strangers, 0 for neighbours, else the fold pair's fold_kept_rest_ (one search).
    double link_of(std::uint32_t i, std::uint32_t j) const;
    std::vector<std::uint32_t> near_mask_;  // grid: bit (dr + 2) * 5 + dc + 2 set for a neighbour at (dr, dc)
    bool far_links_ = false;                // grid: some link spans more than two rows or columns
    std::vector<std::uint64_t> fold_pairs_;   // (i << 32 | j), i < j: the fold pairs (sorted off the grid)
    std::vector<double> fold_kept_rest_;      // kSelfFoldShare x the rest distance of each
    std::vector<std::uint32_t> fold_mask_;    // grid: as near_mask_, the fold pairs only
    std::array<double, 25> longest_fold_kept_rest_{};  // grid: the longest fold_kept_rest_ at (dr, dc)
    bool near_neighbours(std::uint32_t i, int dr, int dc) const { return near_bit(near_mask_, i, dr, dc); }
    bool near_fold_pair(std::uint32_t i, int dr, int dc) const { return near_bit(fold_mask_, i, dr, dc); }
    static bool near_bit(const std::vector<std::uint32_t>& mask, std::uint32_t i, int dr, int dc) {
        return std::abs(dr) <= 2 && std::abs(dc) <= 2 && ((mask[i] >> ((dr + 2) * 5 + (dc + 2))) & 1u) != 0;
    }
    std::vector<int> tile_row_, tile_col_;  // each tile's place in the grid of tiles
    std::vector<std::array<std::uint32_t, 4>> corner_;  // grid: each tile's corner particles (00, 0c, r0, rc)
    std::vector<float> rest_area_;          // grid: twice each tile's rest area, |vector_area| as built
    std::vector<float> tile_rest_;          // grid, per tile: rest diagonals of it alone and with 4 neighbours
    // Off the grid (a mesh cloth): each tile a patch of up to kSelfTile^2 particles grown breadth-first over
    // the links, so compact on the cloth whatever the particles' order; tiles joined by a link are neighbours.
    std::vector<std::uint32_t> member_begin_, member_;           // each tile's particles
    std::vector<std::uint32_t> particle_tile_;                   // each particle's tile
    std::vector<std::uint32_t> tile_link_begin_, tile_link_;     // each tile's neighbour tiles, sorted
    // Scratch, kept between substeps.
    std::vector<Box> boxes_;
    std::vector<std::uint32_t> order_;      // tiles sorted by box.lo.x (the last substep's order)
    std::vector<std::uint8_t> active_;      // 1: within d of a far tile; 2: folded (tested with its neighbours)
    std::vector<glm::vec3> normal_;         // grid: each tile's mean normal
    std::vector<double> area_, diagonals_;  // grid: each tile's |vector area| and |D1| + |D2|
    std::vector<std::uint64_t> tile_pairs_; // (a << 32 | b), a <= b: the tile pairs the narrow phase tests
    std::vector<std::uint64_t> candidates_; // (i << 32 | j), i < j: particle pairs within reach at the last test
    std::vector<double> candidate_kept_;    // each candidate's kept distance
    long long listed_tiles_ = 0;            // tiles the last test sent to the narrow phase
    std::vector<double> pushed_;            // per particle, how far the pushes of this substep moved it (m)
    std::vector<std::uint32_t> pushed_list_; // the particles pushed this substep
    std::vector<TilePoints> points_;
    std::vector<std::uint8_t> gathered_;
    double budget_ = 0.0;                   // closing left before the next test (conservative advancement)
    int skipped_ = 0;                       // substeps skipped since the last test
    int skipped_uncounted_ = 0;             // of them, those with uncounted moves
    double tested_distance_ = 0.0;          // the d the last test was made for (0: none, test at the next substep)

    bool adjacent_tiles(std::uint32_t a, std::uint32_t b) const;
    // Off the grid: the patches (once, from the links), then their neighbours (again whenever the links change).
    void grow_patches();
    void link_patches();
    std::uint32_t tile_of(std::uint32_t particle) const;
    void tile_boxes(const DVec3Array& position);
    // Lists the tile pairs the narrow phase tests: far tiles within d + skin of each other, and each folded
    // tile with itself and its neighbours. Returns how many tiles it marked, and in `budget` the closing the
    // next substeps may spend before a test is needed again (the skin at most when it marked some).
    std::size_t mark_active(const DVec3Array& position, float d, float skin, float reach, double& budget);
    // Pushes apart the listed pairs closer than their kept distance; the pushes come off the budget.
    void resolve(State& state, const CollisionSettings& settings, const DVec3Array& rest_position,
                 SelfCollisionCounts& counts);
    void gather(std::uint32_t t, const State& state, TilePoints& out) const;
};

}  // namespace clothsim
