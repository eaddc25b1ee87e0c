#include "model/element_gather.hpp"

#include "integrators/work_team.hpp"
#include "model/forces.hpp"

#include <glm/geometric.hpp>

#include <algorithm>

namespace clothsim {
namespace {

// Pieces of this many elements or particles per job index: enough work to pay for a claim.
constexpr std::size_t kPiece = 1024;

int pieces(std::size_t count) { return static_cast<int>((count + kPiece - 1) / kPiece); }

}  // namespace

ElementGather ElementGather::for_topology(const Topology& topology) {
    ElementGather g;
    g.springs = topology.springs.size();
    g.hinges = topology.hinges.size();
    const std::size_t n = static_cast<std::size_t>(topology.rows) * static_cast<std::size_t>(topology.cols);
    g.begin.assign(n + 1, 0);
    auto each = [&](auto&& visit) {  // in list order: springs, then hinges
        for (std::size_t j = 0; j < g.springs; ++j) {
            visit(topology.springs[j].a, j * 4 + 0);
            visit(topology.springs[j].b, j * 4 + 1);
        }
        for (std::size_t h = 0; h < g.hinges; ++h) {
            for (std::size_t slot = 0; slot < 4; ++slot) visit(topology.hinges[h].v[slot], (g.springs + h) * 4 + slot);
        }
    };
    each([&](std::uint32_t particle, std::size_t) { ++g.begin[particle + 1]; });
    for (std::size_t i = 0; i < n; ++i) g.begin[i + 1] += g.begin[i];
    g.entry.resize(g.begin[n]);
    std::vector<std::uint32_t> fill(g.begin.begin(), g.begin.end() - 1);
    each([&](std::uint32_t particle, std::size_t entry) { g.entry[fill[particle]++] = static_cast<std::uint32_t>(entry); });
    g.spring_force.resize(g.springs);
    g.hinge_force.resize(g.hinges);
    return g;
}

void gather_spring_forces(const Topology& topology, ElementGather& g, const DVec3Array& position,
                          const SpringSettings& springs, Vec3Array& force, int threads) {
    using Vec = glm::vec3;
    WorkTeam& team = WorkTeam::shared();
    const int spring_pieces = pieces(g.springs), hinge_pieces = pieces(g.hinges);
    // Each element's force, as accumulate_spring_forces computes it (an element it skips gets zero, which adds
    // nothing: a sum that starts at +0 never becomes -0).
    team.run(threads, spring_pieces + hinge_pieces, [&](int piece, int) {
        if (piece < spring_pieces) {
            const std::size_t first = static_cast<std::size_t>(piece) * kPiece, last = std::min(g.springs, first + kPiece);
            for (std::size_t j = first; j < last; ++j) {
                const Spring& s = topology.springs[j];
                const float ks = stiffness_of(springs, s);
                Vec f(0.0f);
                const Vec d(position.get(s.b) - position.get(s.a));
                const float rest = s.rest_length;
                if (ks != 0.0f) {
                    if (rest == 0.0f) {
                        f = ks * d;
                    } else if (const float length = glm::length(d); length > 1e-12f) {
                        f = (ks * (length - rest) / length) * d;
                    }
                }
                g.spring_force.set(j, f);
            }
            return;
        }
        const std::size_t first = static_cast<std::size_t>(piece - spring_pieces) * kPiece;
        const std::size_t last = std::min(g.hinges, first + kPiece);
        for (std::size_t h = first; h < last; ++h) {
            const Hinge& hinge = topology.hinges[h];
            const float kh = stiffness_of(springs, hinge);
            g.hinge_force.set(h, kh == 0.0f ? Vec(0.0f) : kh * Vec(hinge_difference(position, hinge)));
        }
    });
    // Each particle's sum, in list order.
    const std::size_t n = g.begin.size() - 1;
    team.run(threads, pieces(n), [&](int piece, int) {
        const std::size_t first = static_cast<std::size_t>(piece) * kPiece, last = std::min(n, first + kPiece);
        for (std::size_t i = first; i < last; ++i) {
            Vec sum = force.get(i);
            for (std::uint32_t k = g.begin[i]; k < g.begin[i + 1]; ++k) {
                const std::uint32_t element = g.entry[k] >> 2, slot = g.entry[k] & 3u;
                if (element < g.springs) {
                    const Vec f = g.spring_force.get(element);
                    sum += slot == 0 ? f : -f;
                } else {
                    const std::size_t h = element - g.springs;
                    sum += -topology.hinges[h].c[slot] * g.hinge_force.get(h);
                }
            }
            force.set(i, sum);
        }
    });
}

}  // namespace clothsim
