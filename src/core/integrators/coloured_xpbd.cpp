#include "integrators/coloured_xpbd.hpp"

#include "integrators/work_team.hpp"
#include "integrators/xpbd_projection.hpp"
#include "model/forces.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>

namespace clothsim {
namespace {

// Greedy colouring of `count` elements whose particles particles_of(j) lists (Welsh & Powell 1967, in list
// order): element j takes the lowest colour none of its particles has yet. Nullopt past kMaxColours.
template <class Particles>
std::optional<ColouredXpbd::Colours> colour(std::size_t count, std::size_t particle_count, Particles particles_of) {
    std::vector<std::uint64_t> used(particle_count, 0);  // bit c: a coloured element of colour c touches it
    std::vector<std::uint8_t> colour_of(count, 0);
    std::array<std::uint32_t, ColouredXpbd::kMaxColours> size{};
    int colours = 0;
    for (std::size_t j = 0; j < count; ++j) {
        std::uint64_t taken = 0;
        for (std::uint32_t p : particles_of(j)) taken |= used[p];
        if (taken == ~std::uint64_t{0}) return std::nullopt;
        const int c = std::countr_one(taken);
        for (std::uint32_t p : particles_of(j)) used[p] |= std::uint64_t{1} << c;
        colour_of[j] = static_cast<std::uint8_t>(c);
        ++size[static_cast<std::size_t>(c)];
        colours = std::max(colours, c + 1);
    }
    ColouredXpbd::Colours out;
    out.begin.assign(static_cast<std::size_t>(colours) + 1, 0);
    for (int c = 0; c < colours; ++c) out.begin[static_cast<std::size_t>(c) + 1] = out.begin[static_cast<std::size_t>(c)] + size[static_cast<std::size_t>(c)];
    std::vector<std::uint32_t> next(out.begin.begin(), out.begin.end() - 1);
    out.order.resize(count);
    for (std::size_t j = 0; j < count; ++j) out.order[next[colour_of[j]]++] = static_cast<std::uint32_t>(j);
    return out;
}

}  // namespace

std::optional<ColouredXpbd> ColouredXpbd::for_topology(const Topology& topology) {
    std::size_t n = 0;  // the particles the elements reach
    for (const Spring& s : topology.springs) n = std::max<std::size_t>(n, std::max(s.a, s.b) + std::size_t{1});
    for (const Bend& b : topology.bends) n = std::max<std::size_t>(n, std::max({b.a, b.m, b.b}) + std::size_t{1});
    for (const Hinge& h : topology.hinges) n = std::max<std::size_t>(n, *std::max_element(h.v.begin(), h.v.end()) + std::size_t{1});
    ColouredXpbd out;
    auto springs = colour(topology.springs.size(), n, [&](std::size_t j) {
        return std::array<std::uint32_t, 2>{topology.springs[j].a, topology.springs[j].b};
    });
    auto bends = colour(topology.bends.size(), n, [&](std::size_t j) {
        const Bend& b = topology.bends[j];
        return std::array<std::uint32_t, 3>{b.a, b.m, b.b};
    });
    auto hinges = colour(topology.hinges.size(), n, [&](std::size_t j) { return topology.hinges[j].v; });
    if (!springs || !bends || !hinges) return std::nullopt;
    out.springs_ = std::move(*springs);
    out.bends_ = std::move(*bends);
    out.hinges_ = std::move(*hinges);
    return out;
}

void ColouredXpbd::step(State& state, const Dynamics& dynamics, const Topology& topology, const SpringSettings& springs,
                        double h, int threads, XpbdMultipliers& multipliers) {
    const std::size_t n = state.size();
    state.substep = h;
    const bool automatic = threads == 0;
    const int wanted = std::clamp(threads > 0 ? threads : WorkTeam::cores(), 1, WorkTeam::kMaxThreads);
    int team = wanted;
    if (automatic && team > 1 && team_choice_.next_is_single()) team = 1;
    const auto began = std::chrono::steady_clock::now();
    WorkTeam& work_team = WorkTeam::shared();

    // Predict with the external accelerations, as step_xpbd.
    wind_.resize(n);
    dynamics.external(state, wind_);
    accelerations(state, wind_, dynamics.gravity, dynamics.damping, a_);
    start_ = state.position;
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) continue;
        state.position.add(i, state.motion.get(i) + a_.get(i) * (h * h));  // x + h (v + h a)
    }

    multipliers.spring.assign(topology.springs.size(), 0.0);
    multipliers.bend.assign(topology.bends.size(), glm::dvec3(0.0));
    multipliers.hinge.assign(topology.hinges.size(), glm::dvec3(0.0));
    // Each colour in pieces of kPiece elements (small enough that a descheduled thread holds up little:
    // work_team.hpp); each piece's sum of C^2 in its own slot, summed in piece order: the same for any team.
    constexpr std::uint32_t kPiece = 512;
    double violation2 = 0.0;
    auto project = [&](const Colours& colours, auto&& one) {
        for (int c = 0; c < colours.count(); ++c) {
            const std::uint32_t first = colours.begin[static_cast<std::size_t>(c)];
            const std::uint32_t last = colours.begin[static_cast<std::size_t>(c) + 1];
            const int pieces = static_cast<int>((last - first + kPiece - 1) / kPiece);
            violation_.assign(static_cast<std::size_t>(pieces), 0.0);
            work_team.run(team, pieces, [&](int piece, int) {
                const std::uint32_t begin = first + static_cast<std::uint32_t>(piece) * kPiece;
                const std::uint32_t end = std::min(last, begin + kPiece);
                double v = 0.0;
                for (std::uint32_t e = begin; e < end; ++e) v += one(colours.order[e]);
                violation_[static_cast<std::size_t>(piece)] = v;
            });
            for (double v : violation_) violation2 += v;
        }
    };
    project(springs_, [&](std::uint32_t j) {
        const double k = stiffness_of(springs, topology.springs[j]);
        return k != 0.0 ? project_spring(state, topology.springs[j], k, h, multipliers.spring[j]) : 0.0;
    });
    project(bends_, [&](std::uint32_t j) {
        const double k = stiffness_of(springs, topology.bends[j]);
        return k != 0.0 ? project_bend(state, topology.bends[j], k, h, multipliers.bend[j]) : 0.0;
    });
    project(hinges_, [&](std::uint32_t j) {
        const double k = stiffness_of(springs, topology.hinges[j]);
        return k != 0.0 ? project_hinge(state, topology.hinges[j], k, h, multipliers.hinge[j]) : 0.0;
    });

    for (std::size_t i = 0; i < n; ++i) {
        state.motion.set(i, state.pinned[i] ? glm::dvec3(0.0) : state.position.get(i) - start_.get(i));
    }
    multipliers.substep = h;
    multipliers.initial_violation = std::sqrt(violation2);
    if (automatic && wanted > 1) team_choice_.record(team == 1, std::chrono::steady_clock::now() - began);
    last_threads_ = team;
}

}  // namespace clothsim
