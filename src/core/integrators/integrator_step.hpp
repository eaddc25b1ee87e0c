// The one call shape of an integrator's substep (integrator.hpp: IntegratorInfo::substep): everything it reads
// and writes, in one context that MassSpring makes fresh each substep (as Box2D's b2StepContext).
#pragma once

#include "clothsim/integrator.hpp"
#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"

#include "integrators/coloured_xpbd.hpp"
#include "integrators/grid_xpbd.hpp"
#include "integrators/integrators.hpp"
#include "integrators/projective.hpp"

#include <functional>
#include <optional>

namespace clothsim {

// What the integrators keep from substep to substep besides the state: factorisations, XPBD's grid form and
// its multipliers. MassSpring owns one (MassSpring::IterativeSolvers) and invalidates it when the stiffness,
// the substep, the pins or the topology change.
struct IntegratorCaches {
    ProjectiveSolver projective;
    XpbdMultipliers xpbd;
    std::optional<GridXpbd> grid_xpbd;  // XPBD's fast path, made from the topology when it is a grid
    // ... and made from any other topology (a mesh cloth): its elements in colours
    std::optional<ColouredXpbd> coloured_xpbd;
    bool grid_xpbd_current = false;     // grid_xpbd and coloured_xpbd match the topology and the stiffness
    bool grid_xpbd_ran = false;         // the last XPBD substep was the grid form's
    bool coloured_xpbd_ran = false;     // ... the coloured form's
};

struct IntegratorContext {
    State& state;
    const Topology& topology;
    const SimulationSettings& settings;
    const Dynamics& dynamics;  // forces (springs and the rest), external forces (the rest), gravity, damping
    double h;                  // s: the substep
    bool continues;            // nothing but the last substep moved the cloth since (a multistep method's history holds)
    IntegratorCaches& caches;
    // The external forces at the substep's start (wind, contact and a grab; not soft clips), for a method that
    // holds them fixed over the substep (projective).
    std::function<void(Vec3Array&)> frozen_external;
    LinearSolve solve;  // written: the iterations and relative residual of its solve, when it reports one
};

}  // namespace clothsim
