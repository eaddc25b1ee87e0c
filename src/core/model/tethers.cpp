#include "model/tethers.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace clothsim {

namespace {

// Union-find over particle indices, for the clusters of pinned particles.
struct Clusters {
    std::vector<std::uint32_t> parent;
    explicit Clusters(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    std::uint32_t find(std::uint32_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    }
    void join(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

}  // namespace

Tethers build_tethers(const Topology& topology, const State& state, const DVec3Array& rest) {
    const std::size_t n = state.size();
    Clusters clusters(n);
    for (const Spring& s : topology.springs) {
        if (state.pinned[s.a] == kPinned && state.pinned[s.b] == kPinned) clusters.join(s.a, s.b);
    }
    // Each cluster's members, clusters in order of their root.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> members;  // (root, particle)
    for (std::uint32_t i = 0; i < n; ++i) {
        if (state.pinned[i] == kPinned) members.emplace_back(clusters.find(i), i);
    }
    std::sort(members.begin(), members.end());
    std::vector<std::size_t> begin;  // cluster c is members[begin[c], begin[c + 1])
    for (std::size_t k = 0; k < members.size(); ++k) {
        if (k == 0 || members[k].first != members[k - 1].first) begin.push_back(k);
    }
    begin.push_back(members.size());
    const std::size_t cluster_count = begin.size() - 1;

    Tethers out;
    std::vector<std::pair<double, std::uint32_t>> nearest(cluster_count);  // (distance, anchor) per cluster
    for (std::uint32_t i = 0; i < n && cluster_count > 0; ++i) {
        if (state.pinned[i] != 0) continue;  // pinned, or absent
        const glm::dvec3 p = rest.get(i);
        for (std::size_t c = 0; c < cluster_count; ++c) {
            nearest[c] = {std::numeric_limits<double>::infinity(), 0u};
            for (std::size_t k = begin[c]; k < begin[c + 1]; ++k) {
                const std::uint32_t a = members[k].second;
                nearest[c] = std::min(nearest[c], {glm::length(rest.get(a) - p), a});
            }
        }
        const std::size_t kept = std::min<std::size_t>(cluster_count, kMaxTethersPerParticle);
        std::partial_sort(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(kept), nearest.end());
        // Farthest first: when pins moved apart ask for more than the cloth can give (a pin dragged away from
        // the others), the nearest pin's tether is projected last and wins, so the cloth next to a dragged
        // pin follows it.
        std::reverse(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(kept));
        for (std::size_t c = 0; c < kept; ++c) {
            out.particle.push_back(i);
            out.anchor.push_back(nearest[c].second);
            out.rest.push_back(nearest[c].first);
        }
    }
    return out;
}

std::size_t project_tethers(State& state, const Tethers& tethers, double strain) {
    return project_tethers(state, tethers, strain, 0, tethers.size());
}

std::size_t first_tether_from(const Tethers& tethers, std::uint32_t particle) {
    return static_cast<std::size_t>(std::lower_bound(tethers.particle.begin(), tethers.particle.end(), particle) -
                                    tethers.particle.begin());
}

std::size_t project_tethers(State& state, const Tethers& tethers, double strain, std::size_t first, std::size_t last) {
    std::size_t active = 0;
    last = std::min(last, tethers.size());
    for (std::size_t t = first; t < last; ++t) {
        const std::uint32_t i = tethers.particle[t];
        const glm::dvec3 anchor = state.position.get(tethers.anchor[t]);
        const glm::dvec3 d = state.position.get(i) - anchor;
        const double longest = (1.0 + strain) * tethers.rest[t];
        const double length2 = glm::dot(d, d);
        if (!(length2 > longest * longest)) continue;  // within reach (or NaN: left to the guard)
        ++active;
        const double length = std::sqrt(length2);
        const glm::dvec3 n = d / length;
        state.position.set(i, anchor + n * longest);
        const double away = glm::dot(state.motion.get(i), n);
        if (away > 0.0) state.motion.add(i, -away * n);
    }
    return active;
}

}  // namespace clothsim
