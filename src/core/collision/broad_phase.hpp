// Broad phase of the collision stage: axis-aligned boxes around blocks of consecutive particles (runs of at
// most kBlockParticles along a grid row, so a block is a short piece of cloth; runs of the particle list
// otherwise), and conservative tests of whether a collider can touch anything in a box. A collider is then tested particle by particle only on the blocks it may touch; a
// collider out of reach of every block costs one box test per block.
//
// The tests are conservative: every particle whose contact depth (colliders.hpp) is positive lies in a box
// the test accepts (they allow a relative margin of 1e-5 for rounding), so culling never changes a result.
#pragma once

#include "clothsim/bounding_box.hpp"
#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include <glm/vec3.hpp>

#include <cmath>
#include <cstddef>
#include <vector>

namespace clothsim {

// Particles per block. Smaller blocks cull more of a cloth draped over a collider, larger ones cost fewer box
// tests; 16 is two AVX2 vectors (docs/PERFORMANCE.md has the drape figures).
inline constexpr std::size_t kBlockParticles = 16;


// The box around particles [begin, end); NaN coordinates are left out (a NaN particle touches nothing).
// Positions are double and boxes float: a bound is rounded to the nearest float, within the tests' margin.
Box particle_bounds(const DVec3Array& position, std::size_t begin, std::size_t end);

// `bounds` widened by the motions of particles [begin, end), in double (NaN components are left out):
// self-collision's pass when the fast solver's sweep did not leave them (fast_solver.hpp).
void include_motion(const DVec3Array& motion, std::size_t begin, std::size_t end, MotionBounds& bounds);

// The box around boxes[0, n) (empty for n = 0), as glm::min and glm::max fold them: a NaN bound is left out.
Box union_of(const Box* boxes, std::size_t n);

// What the collision stage reads of a block's box. A plane (a half-space below a height) reads only the
// box's lowest y (may_touch), so when no other collider can reach the cloth each block needs only its lowest
// point: a Lowest box is that bound with its other five sides open (+-infinity), still a conservative box,
// found with one axis and one reduction instead of six (colliders.hpp: block_bounds_for chooses).
enum class BlockBounds { Box, Lowest };

// The boxes of the blocks of `count` particles from `begin` (one grid row): runs of kBlockParticles. With
// BlockBounds::Lowest, each block's lowest point in an otherwise open box (empty when no y is a number).
void row_block_bounds(const DVec3Array& position, std::size_t begin, std::size_t count, Box* out,
                      BlockBounds bounds = BlockBounds::Box);

// Block k holds particles [start[k], start[k + 1]). For a rows x cols grid (rows * cols == particles) the
// blocks are runs of at most kBlockParticles along each row, in row order: row r's j-th run is block
// r * blocks_per_row(cols) + j, the layout the fast solver fills its boxes in.
std::vector<std::size_t> block_starts(std::size_t particles, int rows, int cols);
inline std::size_t blocks_per_row(int cols) { return (static_cast<std::size_t>(cols) + kBlockParticles - 1) / kBlockParticles; }

// Whether a particle in a box can come closer than `thickness` to a collider's surface: each shape's may_touch
// (shapes/).

}  // namespace clothsim
