// XPBD on the grid: the `xpbd` integrator's fast path (solver.method = "fast" on a grid cloth).
//
// The same method as step_xpbd (integrators.hpp: Macklin et al. 2016, one projection per substep as in
// "Small Steps", Macklin et al. 2019), with the same arithmetic per constraint, in another order. step_xpbd
// projects the springs in list order, each waiting for the positions the one before it wrote: a chain of
// square roots and divides that no core overlaps (docs/STIFF_CLOTH.md). Here the grid's elements are
// projected in batches of elements that share no particle, so each batch is one vector loop. The order is the
// builder's (cloth_builder.cpp), direction by direction, each from the top row down:
//  - the springs along the rows (structural), each row in two passes: the springs from every second column,
//    then the others;
//  - the springs down (structural), down right and down left (shear), one batch per row;
//  - skip-one springs along the rows in three passes per row (every third column), then down;
//  - then the bends (spring.hpp): along the rows in three passes per row, then down, one batch per row.
// So a correction travels down the cloth through a whole column in one pass, as in list order; along a
// row it travels one spring per pass instead of the whole row. A pass along a row reads its elements' data
// contiguously (slot()) and its particles two or three apart; the AVX2 kernel loads them as contiguous
// vectors and transposes them in registers (grid_xpbd.cpp).
// Interleaving the directions row by row instead (all of row r's springs, then row r + 1's) lets a
// correction travel one row per pass: a cloth that hits a collider hard stretches far more (docs/
// STIFF_CLOTH.md, "Rejected designs").
// Gauss-Seidel in this order is the list-order projection in another order: step_xpbd on the same topology
// with its springs and bends listed in this order gives the same positions bit for bit (the tests check it).
// Every kernel (generic, AVX2, AVX-512, FastSolver's choice) gives the same positions too; only the sum of
// the violations that the residual is relative to may round differently.
#pragma once

#include "integrators/integrators.hpp"
#include "integrators/team_choice.hpp"

#include <array>
#include <optional>
#include <vector>

namespace clothsim {

class GridXpbd {
public:
    // Nullopt when the topology is not a rows x cols grid whose springs and bends all run in the six grid
    // directions (at most one per slot).
    static std::optional<GridXpbd> for_topology(const Topology& topology);

    // Every element's k w from the settings; call after the springs' settings change.
    void set_stiffness(const Topology& topology, const SpringSettings& springs);

    // One substep: predict with the external accelerations (gravity, wind, damping), project every element
    // once, motion = x' - x. As step_xpbd. `threads` (0: one per core, or one alone while that is faster:
    // team_choice.hpp) share the work in small pieces (work_team.hpp); the result is the same for any thread
    // count.
    void step(State& state, const Dynamics& dynamics, double h, int threads);
    // The threads `requested` really gives: at most one per band of kBandRows rows.
    int effective_threads(int requested) const;
    // The threads the last substep ran on.
    int last_threads() const { return last_threads_; }

    static constexpr int kBandRows = 32;

    // |C(x) + alpha~ lambda| / |C(prediction)| at `position`, as xpbd_residual (0 before a substep).
    double residual(const DVec3Array& position) const;

private:
    GridXpbd(int rows, int cols) : rows_(rows), cols_(cols) {}
    void set_substep(double h);

    int rows_, cols_;
    bool bends_ = false;  // directions 4 and 5 hold bends, not skip-one springs
    // The slot of direction d's element that starts at particle `start`, and back. Down the cloth (d = 1, 2, 3, 5)
    // the slot is the start particle; along a row (d = 0 and 4, span 1 and 2 columns) a row's slots hold its
    // elements by pass, each pass's (every (span + 1)th column) in column order, so a pass reads them contiguously.
    std::size_t slot(int d, std::size_t start) const;
    std::size_t start_of(int d, std::size_t slot) const;

    // Per direction d (fast_solver.cpp's six: (0,1) (1,0) (1,1) (1,-1) (0,2) (2,0)), per slot (slot()):
    std::array<std::vector<int>, 6> source_;     // the element's index in topology.springs or .bends, -1 none
    std::array<std::vector<float>, 6> k_;        // k w (N/m), 0 for none
    std::array<std::vector<float>, 6> rest_;     // L0 (m) of a spring
    std::array<std::vector<double>, 6> alpha_;   // 1 / (k w h^2), infinite for none
    std::array<std::vector<double>, 6> lambda_;  // the last substep's multiplier of a spring
    std::array<DVec3Array, 2> bend_lambda_;      // ... of a bend along direction 4 + k (a vector constraint)
    std::array<std::array<int, 3>, 2> first_slot_{};  // [span - 1][phase]: a pass's first slot in a row
    std::array<bool, 6> present_{};              // some element has k > 0 in direction d
    double alpha_h_ = 0.0;                       // the substep alpha_ is for (0: not set)
    std::array<SpringCurve, 2> curve_{};        // the structural springs' stretch curves (set_stiffness)
    double substep_ = 0.0;                       // the last substep's length, 0 before one
    double initial_violation_ = 0.0;
    // Scratch kept across substeps.
    Vec3Array wind_;
    DVec3Array a_, start_;
    TeamChoice team_choice_;               // threads = 0: the team, or one thread while it is faster
    int last_threads_ = 1;
};

}  // namespace clothsim
