#include "model/tearing.hpp"

#include "model/gaussian_curvature.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <numeric>
#include <unordered_set>
#include <vector>

namespace clothsim {
namespace {

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | b;
}

// The grid particle halfway between a and b (two apart on a row or column).
std::uint32_t middle(const Topology& t, std::uint32_t a, std::uint32_t b) {
    const int ra = static_cast<int>(a) / t.cols, ca = static_cast<int>(a) % t.cols;
    const int rb = static_cast<int>(b) / t.cols, cb = static_cast<int>(b) % t.cols;
    return static_cast<std::uint32_t>(t.index((ra + rb) / 2, (ca + cb) / 2));
}

}  // namespace

std::size_t tear_springs(Topology& topology, const DVec3Array& position, float tear_strain) {
    return break_springs(topology, [&](const Spring& s) {
        if (s.rest_length <= 0.0f) return false;
        const double length = glm::length(position.get(s.b) - position.get(s.a));
        return length > (1.0 + double(tear_strain)) * s.rest_length;  // false for NaN
    });
}

std::size_t break_springs(Topology& topology, const std::function<bool(const Spring&)>& breaks) {
    std::unordered_set<std::uint64_t> broken;
    for (const Spring& s : topology.springs) {
        if (s.kind != SpringKind::Bending && breaks(s)) broken.insert(pair_key(s.a, s.b));
    }
    // Skip-one bending springs break on their own account, or with a segment they span.
    auto bridges = [&](std::uint32_t a, std::uint32_t m, std::uint32_t b) {
        return broken.count(pair_key(a, m)) != 0 || broken.count(pair_key(m, b)) != 0;
    };
    const std::size_t before = topology.springs.size() + topology.bends.size() + topology.hinges.size();
    std::erase_if(topology.springs, [&](const Spring& s) {
        if (s.kind != SpringKind::Bending) return broken.count(pair_key(s.a, s.b)) != 0;
        return breaks(s) || (topology.cols > 0 && !topology.mesh && bridges(s.a, middle(topology, s.a, s.b), s.b));
    });
    std::erase_if(topology.bends, [&](const Bend& b) { return bridges(b.a, b.m, b.b); });
    // A hinge goes with its edge, or with either triangle it joins.
    std::erase_if(topology.hinges, [&](const Hinge& h) {
        for (const auto& [a, b] : {std::pair{0, 1}, {0, 2}, {1, 2}, {0, 3}, {1, 3}}) {
            if (broken.count(pair_key(h.v[a], h.v[b])) != 0) return true;
        }
        return false;
    });
    const std::size_t removed = before - topology.springs.size() - topology.bends.size() - topology.hinges.size();
    if (removed == 0) return 0;
    // A membrane triangle goes with any of its edges, as the triangle it is.
    std::erase_if(topology.membranes, [&](const Membrane& m) {
        return broken.count(pair_key(m.v[0], m.v[1])) != 0 || broken.count(pair_key(m.v[1], m.v[2])) != 0 ||
               broken.count(pair_key(m.v[2], m.v[0])) != 0;
    });
    const std::size_t triangles = topology.triangles.size();
    std::erase_if(topology.triangles, [&](const std::array<std::uint32_t, 3>& t) {
        return broken.count(pair_key(t[0], t[1])) != 0 || broken.count(pair_key(t[1], t[2])) != 0 ||
               broken.count(pair_key(t[2], t[0])) != 0;
    });
    if (topology.triangles.size() != triangles) {
        topology.cell_triangles = false;
        if (!topology.gaussian.rim_corners.empty()) {  // the cut's sides join the rim
            find_rim(topology.gaussian, topology.triangles, static_cast<std::size_t>(topology.rows) * topology.cols);
        }
    }
    topology.count_by_kind();
    return removed;
}

std::vector<std::uint32_t> connected_pieces(const Topology& topology, std::size_t particles) {
    // Union-find with path halving.
    std::vector<std::uint32_t> parent(particles);
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](std::uint32_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    };
    auto join = [&](std::uint32_t a, std::uint32_t b) {
        a = find(a);
        b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    };
    for (const Spring& s : topology.springs) join(s.a, s.b);
    for (const Bend& b : topology.bends) {
        join(b.a, b.m);
        join(b.m, b.b);
    }
    for (std::size_t i = 0; i < particles; ++i) parent[i] = find(static_cast<std::uint32_t>(i));
    return parent;
}

}  // namespace clothsim
