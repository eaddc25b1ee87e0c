// Spring strain: how far the springs are stretched, e = |x_b - x_a| / L0 - 1 (0.05 = 5% longer than at rest).
// A diagnostic read at the end of a run (`--json` reports max_strain); the simulation never uses it.
#pragma once

#include "clothsim/spring.hpp"
#include "clothsim/state.hpp"

namespace clothsim {

// The largest strain |x_b - x_a| / L0 - 1 over the springs of `kind` (negative when every one is shorter than
// at rest). NaN when the topology has no spring of that kind with L0 > 0, or when a position is not finite.
double max_strain(const Topology& topology, const DVec3Array& position, SpringKind kind);

// The largest strain of the springs that carry the membrane: structural and shear. Bending springs are left
// out: they span two cells and shorten whenever the cloth folds, so their length says nothing about stretch.
double max_membrane_strain(const Topology& topology, const DVec3Array& position);

}  // namespace clothsim
