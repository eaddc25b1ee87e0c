// Self-intersections: pairs of the cloth's triangles that pass through each other.
// A diagnostic read at the end of a run (`--json` reports self_intersections) and by the tests of
// self-collision (self_collision.hpp); the simulation never uses it.
#pragma once

#include "clothsim/state.hpp"

#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <vector>

namespace clothsim {

// Whether segment pq meets triangle abc (touching counts), in double precision (signs of plain double
// products, not an exact predicate; a degenerate, zero-area triangle is never met): the ends lie on opposite sides of the
// triangle's plane (or on it), and the point where the segment meets the plane lies inside the triangle
// (barycentric signs, all >= 0). Locating the point, rather than testing the line's orientation against
// the edges, stays right for a segment nearly in the plane (a flat sheet whose float positions are off the
// plane by rounding): the point is then on the segment, inside the triangle only if they overlap. A
// segment lying in the plane (both ends exactly on it) does not count.
bool segment_meets_triangle(const glm::dvec3& p, const glm::dvec3& q, const glm::dvec3& a, const glm::dvec3& b,
                            const glm::dvec3& c);

// Whether two triangles that share no vertex intersect: an edge of one meets the other.
bool triangles_intersect(const std::array<glm::dvec3, 3>& t, const std::array<glm::dvec3, 3>& u);

// The pairs of the topology's triangles that share no vertex and intersect, at `position` (the positions the
// renderer draws, float, tested in double). Absent triangles are not in the topology; a NaN corner leaves
// its triangle out. Broad phase: the triangles' boxes swept along x.
std::size_t intersecting_triangle_pairs(const Topology& topology, const std::vector<glm::vec3>& position);

}  // namespace clothsim
