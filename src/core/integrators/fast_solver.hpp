// The fast solver for grid cloth.
//
// Design (see docs/PERFORMANCE.md for the figures):
//  - Springs of a grid come in six directions: structural (0,+1) (+1,0), shear (+1,+1) (+1,-1), bending
//    (0,+2) (+2,0), where bending is either skip-one springs or bends (spring.hpp: the three particles
//    from the start along (0,+1) or (+1,0)). The elements of one direction starting in one row are a
//    contiguous run of particles paired with shifted runs, so their forces are computed by one vector loop
//    (AVX-512 or AVX2 + FMA when the CPU has it, chosen at run time; plain C++ otherwise), each once.
//  - Weights (spring.hpp): the largest in a row scales the row's k; the columns whose weight differs (the
//    cloth's edge, slots outside a disc, where the weight is 0) scale their computed forces afterwards. All
//    are powers of two or 0, so the result is the textbook's k w product bit for bit.
//  - One pass over the rows does everything a substep needs. Row q's force is complete once the spring
//    rows q-2, q-1 and q are computed, and no later spring reads row q, so the sweep gathers row q's force
//    from those three spring rows (kept in a rolling window that stays in L1/L2), integrates it in place
//    (position Verlet) and, while the row is still in L1, writes the boxes of its particle blocks for the
//    collision broad phase. Collisions are not part of the sweep: the caller's collision stage runs after
//    it (collide_stage in colliders.hpp).
//  - The state is double (state.hpp): the spring kernels take each difference in double and round it to
//    float, the row update adds a float change to the double motion. Every particle's data is read and
//    written once. AVX-512 (when the CPU has it) does the differences and the update 8 doubles at a time.
//  - The rows are cut into bands, a few per thread, which the threads of the WorkTeam take one at a time
//    (work_team.hpp: a descheduled thread delays one band, not the substep). The only springs that read
//    across a band boundary are the two spring rows just above it; they are computed first, into shared
//    storage, and both neighbouring bands use the stored values. Each particle's force is summed in the
//    same order for any partition, so the result is bit-identical for any band and thread count.
#pragma once

#include "collision/broad_phase.hpp"
#include "clothsim/settings.hpp"
#include "clothsim/state.hpp"
#include "integrators/team_choice.hpp"

#include <array>
#include <functional>
#include <optional>
#include <vector>

namespace clothsim {

// The instruction sets the fast solver has kernels for, chosen at run time (the best the CPU has).
enum class FastKernel { Generic, Avx2, Avx512 };

class FastSolver {
public:
    // Nullopt when the topology is not a rows x cols grid whose springs and bends all run in the six
    // directions (at most one per slot, weights powers of two or 0).
    static std::optional<FastSolver> for_topology(const Topology& topology);

    // One substep: the spring kinds in `spring_mask` (bit k: SpringKind k; step_plan.hpp) plus `external`
    // forces (N per particle, or null), and the Verlet update with gravity and damping. Collisions are the
    // caller's next stage; for it, `row_boxes` (when not null) receives the box of every block of
    // block_starts(rows x cols) after the update (only its lowest point with BlockBounds::Lowest), and
    // `motion_bounds` (when not null) the bounds of every particle's new motion, each row's taken in its
    // update (for self-collision, self_collision.hpp, and the colliders' swept boxes, colliders.hpp). With
    // `row_boxes`, `band_unions` (when not null, kMaxBands entries) receives the union of each band's boxes,
    // made on the band's thread, the rest empty: the cloth's box without reading every block's box again.
    void step(State& state, const SimulationSettings& settings, unsigned spring_mask, const Vec3Array* external,
              double h, double damping, std::vector<Box>* row_boxes, MotionBounds* motion_bounds = nullptr,
              BlockBounds bounds = BlockBounds::Box, Box* band_unions = nullptr);

    // Threads the solver will really use for `requested` (0 = one per core): at most one per 8 rows.
    int effective_threads(int requested) const;
    // The bands `threads` threads split the rows into: kBandsPerThread each (one when alone), at least 8 rows
    // each, at most kMaxBands.
    int band_count(int threads) const;
    static constexpr int kBandsPerThread = 4, kMaxBands = 64;
    // With threads = 0: whether the last substeps ran on one thread because the team was slower.
    bool team_set_aside() const { return team_.single(); }
    // Runs work(band, row_begin, row_end) over all rows, split as the last substep's sweep split them, on as
    // many threads (all rows on this thread when the last substep ran on one): a stage that touches each
    // particle on its own (the tethers, the collision boxes) then finds most bands in the caches of a core
    // that has just written them. Bands are numbered from 0, at most kMaxBands of them.
    void for_each_band(const std::function<void(int, int, int)>& work) const;
    // The best kernel this CPU runs, and the one in use (the best unless a test chose another).
    static FastKernel best_kernel();
    static FastKernel kernel();
    static const char* kernel_name(FastKernel kernel = FastSolver::kernel());
    // For tests: run `kernel` (one the CPU has; another goes back to the best) and return the one in use
    // before. Not for use while a step runs.
    static FastKernel use_kernel(FastKernel kernel);

private:
    FastSolver(int rows, int cols) : rows_(rows), cols_(cols) {}

    struct Scratch {
        AlignedVector<float> window;  // the last three spring rows (6 directions x 3 components, padded)
        // The running bounds of the motion of the rows this band's sweep updated, when asked for: 8 lanes of
        // lo and of hi per component (fast_solver.cpp).
        alignas(64) std::array<double, 48> motion_lanes{};
        Box box_union;  // the union of the boxes this band's sweep made, when it made them
    };
    struct SweepSettings {
        const SimulationSettings& settings;
        unsigned mask;
        const Vec3Array* external;
        double h;
        double damping;  // 1/s: MassSpring::damping_rate()
        Box* row_boxes;
        BlockBounds bounds;
        bool motion_bounds;
    };
    // The first row of band b of `bands`: rows are split as evenly as whole rows allow.
    int band_begin(int b, int bands) const { return static_cast<int>(static_cast<long long>(rows_) * b / bands); }
    void sweep(State& state, const SweepSettings& sweep, int begin, int end, Scratch& scratch,
               const std::vector<int>& boundary_slot);
    // Forces of the springs of the kinds in `mask` starting in row r, into out[d][component][c] (6 x 3 x cols).
    void spring_row(const State& state, const SpringSettings& springs, unsigned mask, int r, float* out) const;

    int rows_, cols_;
    std::array<AlignedVector<float>, 6> rest_;  // rest length of the spring leaving particle i in direction d
    std::array<bool, 6> present_{};            // the topology has springs in direction d (all of them, or none)
    bool bends_ = false;                       // directions 4 and 5 are bends, not skip-one springs
    std::array<std::vector<float>, 6> row_weight_;  // the largest weight of direction d's elements in row r
    // (column, weight / row weight) of the elements of row r that differ: fixes_[d][fix_begin_[d][r] ...
    // fix_begin_[d][r + 1]).
    std::array<std::vector<int>, 6> fix_begin_;
    std::array<std::vector<std::pair<int, float>>, 6> fixes_;
    int bands_ = 0;                           // the band count the buffers below are laid out for
    std::vector<Scratch> scratch_;             // one per band
    AlignedVector<float> boundary_;            // spring rows just above band boundaries
    AlignedVector<float> zeros_;               // a spring row of zeros: the rows above row 0
    std::vector<int> boundary_slot_;           // per spring row: its slot in boundary_, or -1
    std::vector<int> no_boundary_;             // all -1: one band sweeping every row
    TeamChoice team_;                          // solver.threads = 0: the team, or one thread when it is faster
    int last_bands_ = 1;                       // the bands of the last substep (1: it ran on one thread)
    int last_threads_ = 1;                     // the threads of the last substep
};

}  // namespace clothsim
