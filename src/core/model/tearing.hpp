// Tearing: a spring stretched beyond springs.tear_strain breaks, and what it held together comes apart.
//
// Checked once per step (MassSpring::step, the Tear stage; skipped while tear_strain is 0). A spring with
// (|d| - L0) / L0 > tear_strain is removed from the topology. With a structural spring go the elements that
// bridge it: a skip-one bending spring or a bend whose middle segment it was (else they would hold the two
// sides together), and the triangles that have it as an edge (so no triangle is drawn or exported across
// the tear). Removing a spring removes equal and opposite forces, so momentum is kept, and its stored energy
// leaves with it, so the energy never rises at a tear. Cutting (MassSpring::cut: the app's shift + right-drag)
// removes the springs a stroke crosses the same way.
#pragma once

#include "clothsim/state.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>

namespace clothsim {

// Removes every spring for which `breaks` is true, and the bends, bending springs and triangles that bridge a
// removed structural or shear spring; clears cell_triangles when a triangle goes. Returns how many springs
// (of any kind, bends included) were removed.
std::size_t break_springs(Topology& topology, const std::function<bool(const Spring&)>& breaks);
// break_springs for the springs strained beyond `tear_strain` at `position`.
std::size_t tear_springs(Topology& topology, const DVec3Array& position, float tear_strain);

// Per particle, a label of the piece it belongs to: particles joined by springs or bends share it.
std::vector<std::uint32_t> connected_pieces(const Topology& topology, std::size_t particles);

}  // namespace clothsim
