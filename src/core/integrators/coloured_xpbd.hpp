// XPBD on any topology, in colours: the `xpbd` integrator's fast path for a cloth that is not a grid (a mesh
// cloth; solver.method = "fast").
//
// The same method and arithmetic per constraint as step_xpbd (integrators.hpp: Macklin et al. 2016, one
// projection per substep as in "Small Steps", Macklin et al. 2019), in another order. step_xpbd projects the
// elements in list order, each waiting for the positions the one before wrote, so no two can run at once.
// Here each kind of element (springs, then bends, then hinges, then membranes, as step_xpbd) is split into colours by a greedy
// graph colouring (each element takes the lowest colour that no element sharing a particle with it has taken
// yet, in list order; Welsh & Powell 1967's greedy scheme, as in Fratarcangeli & Pellacini 2015 for
// position-based dynamics on the GPU). The elements of one colour share no particle: each reads and writes
// only its own particles, so a colour runs on the whole team at once, and its result does not depend on the
// order within it or on the thread count. Gauss-Seidel in this order is the list-order projection of the
// elements listed colour by colour (each colour's in list order): step_xpbd on such a topology gives the same
// positions bit for bit (the tests check it). Only the sum of the violations that the residual is relative to
// may round differently (it is summed piece by piece).
#pragma once

#include "integrators/integrators.hpp"
#include "integrators/team_choice.hpp"
#include "model/membrane.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace clothsim {

class ColouredXpbd {
public:
    // The colouring of `topology`'s springs, bends and hinges; nullopt when some element would need more than
    // kMaxColours colours (a particle in more than about 32 elements of one kind: not a cloth), and the list
    // path runs instead.
    static std::optional<ColouredXpbd> for_topology(const Topology& topology);
    static constexpr int kMaxColours = 64;

    // Every element's k w from the settings; call after the springs' settings change.
    void set_stiffness(const Topology& topology, const SpringSettings& springs);

    // One substep: predict with the external accelerations (gravity, wind, damping), project every element
    // once colour by colour, motion = x' - x; the multipliers by element index in `multipliers` (for
    // xpbd_residual). `threads` (0: one per core, or one alone while that is faster: team_choice.hpp) share each
    // colour; the result is the same for any thread count.
    void step(State& state, const Dynamics& dynamics, const Topology& topology, const SpringSettings& springs,
              double h, int threads, XpbdMultipliers& multipliers);
    // The threads the last substep ran on.
    int last_threads() const { return last_threads_; }

    // Each kind's elements in colour order (indices into topology.springs, .bends, .hinges), and where each
    // colour begins in it (colours + 1 entries).
    struct Colours {
        std::vector<std::uint32_t> order;
        std::vector<std::uint32_t> begin;
        int count() const { return static_cast<int>(begin.size()) - 1; }
    };
    const Colours& springs() const { return springs_; }
    const Colours& bends() const { return bends_; }
    const Colours& hinges() const { return hinges_; }
    const Colours& membranes() const { return membranes_; }

private:
    ColouredXpbd() = default;
    void set_substep(double h);
    // One element of a colour pass (entry e of the colour order), and a run [begin, end) of them eight at a time
    // with AVX-512; each returns its sum of C^2, added element by element.
    double spring_one(State& state, std::uint32_t e, XpbdMultipliers& multipliers) const;
    double hinge_one(State& state, std::uint32_t e, XpbdMultipliers& multipliers) const;
    double springs_avx512(State& state, std::uint32_t begin, std::uint32_t end, XpbdMultipliers& multipliers) const;
    double hinges_avx512(State& state, std::uint32_t begin, std::uint32_t end, XpbdMultipliers& multipliers) const;
    double membranes_avx512(State& state, const Topology& topology, const SpringSettings& springs, std::uint32_t begin,
                            std::uint32_t end, const MembraneTensor& c, double h, XpbdMultipliers& multipliers) const;

    Colours springs_, bends_, hinges_, membranes_;
    // The springs' and hinges' data in colour order (entry e is element order[e]), what a colour's pass reads
    // contiguously: particles, rest lengths and weights, k w (0: not projected) and alpha~ = 1 / (k w h^2).
    struct SpringData {
        std::vector<std::int32_t> a, b;
        std::vector<double> rest, k, alpha;
        std::vector<SpringCurve> curve;  // each spring's, when the cloth has curves (has_curves); else empty
    } spring_data_;
    struct HingeData {
        std::array<std::vector<std::int32_t>, 4> v;
        std::array<std::vector<double>, 4> c;
        std::vector<double> k, alpha;
    } hinge_data_;
    // The membranes' data in colour order: corners, weights and rest areas, in double.
    struct MembraneData {
        std::array<std::vector<std::int32_t>, 3> v;
        std::array<std::vector<double>, 3> bu, bv;
        std::vector<double> area;
    } membrane_data_;
    double alpha_h_ = 0.0;  // the substep alpha is for (0: not set)
    DVec3Array a_, start_;
    Vec3Array wind_;
    std::vector<double> violation_;  // per piece of a colour: its sum of C^2
    TeamChoice team_choice_;
    int last_threads_ = 1;
};

}  // namespace clothsim
