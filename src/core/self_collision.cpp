#include "clothsim/self_collision.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace clothsim {
namespace {

constexpr std::uint32_t kSelfTileParticles = kSelfTile * kSelfTile;

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | b;
}

// Whether boxes a and b come within `reach` of each other (per axis).
bool within(const Box& a, const Box& b, float reach) {
    return a.lo.x <= b.hi.x + reach && b.lo.x <= a.hi.x + reach && a.lo.y <= b.hi.y + reach &&
           b.lo.y <= a.hi.y + reach && a.lo.z <= b.hi.z + reach && b.lo.z <= a.hi.z + reach;
}

}  // namespace

double particle_spacing(const Topology& topology) {
    double spacing = 0.0;
    for (const Spring& s : topology.springs) {
        if (s.kind == SpringKind::Structural) spacing = std::max(spacing, static_cast<double>(s.rest_length));
    }
    return spacing;
}

SelfCollision::SelfCollision(const Topology& topology, const DVec3Array& rest_position)
    : rows_(topology.rows), cols_(topology.cols), particles_(rest_position.size()) {
    grid_ = rows_ > 0 && cols_ > 0 && static_cast<std::size_t>(rows_) * cols_ == particles_;
    if (grid_) {
        tile_rows_ = (rows_ + kSelfTile - 1) / kSelfTile;
        tile_cols_ = (cols_ + kSelfTile - 1) / kSelfTile;
    } else {
        tile_rows_ = 1;
        tile_cols_ = static_cast<int>((particles_ + kSelfTileParticles - 1) / kSelfTileParticles);
    }
    spacing_ = particle_spacing(topology);
    update_neighbours(topology);
    // The rest diagonal of each tile alone and with its neighbours to the right, below, below right and
    // below left: the longer distance between opposite corner particles of the region.
    if (grid_) {
        tile_rest_.assign(static_cast<std::size_t>(tile_rows_) * tile_cols_ * 5, 0.0f);
        auto corner = [&](int r, int c) { return rest_position.get(static_cast<std::size_t>(r) * cols_ + c); };
        auto diagonal = [&](int r0, int c0, int r1, int c1) {  // rows r0..r1, cols c0..c1 of tiles
            const int pr0 = r0 * kSelfTile, pc0 = c0 * kSelfTile;
            const int pr1 = std::min(rows_, (r1 + 1) * kSelfTile) - 1, pc1 = std::min(cols_, (c1 + 1) * kSelfTile) - 1;
            return static_cast<float>(std::max(glm::length(corner(pr1, pc1) - corner(pr0, pc0)),
                                               glm::length(corner(pr1, pc0) - corner(pr0, pc1))));
        };
        for (int r = 0; r < tile_rows_; ++r) {
            for (int c = 0; c < tile_cols_; ++c) {
                float* rest = tile_rest_.data() + (static_cast<std::size_t>(r) * tile_cols_ + c) * 5;
                rest[0] = diagonal(r, c, r, c);
                if (c + 1 < tile_cols_) rest[1] = diagonal(r, c, r, c + 1);
                if (r + 1 < tile_rows_) rest[2] = diagonal(r, c, r + 1, c);
                if (r + 1 < tile_rows_ && c + 1 < tile_cols_) rest[3] = diagonal(r, c, r + 1, c + 1);
                if (r + 1 < tile_rows_ && c > 0) rest[4] = diagonal(r, c - 1, r + 1, c);
            }
        }
    }
    const std::size_t tiles = static_cast<std::size_t>(tile_rows_) * tile_cols_;
    order_.resize(tiles);
    tile_row_.resize(tiles);
    tile_col_.resize(tiles);
    for (std::size_t t = 0; t < tiles; ++t) {
        order_[t] = static_cast<std::uint32_t>(t);
        tile_row_[t] = static_cast<int>(t) / tile_cols_;
        tile_col_[t] = static_cast<int>(t) % tile_cols_;
    }
}

void SelfCollision::update_neighbours(const Topology& topology) {
    // Compressed rows: count, fill, then sort and drop repeats within each particle's run.
    std::vector<std::uint32_t> begin(particles_ + 1, 0);
    auto each_link = [&](auto&& link) {
        for (const Spring& s : topology.springs) link(s.a, s.b);
        for (const Bend& b : topology.bends) {
            link(b.a, b.m);
            link(b.m, b.b);
            link(b.a, b.b);
        }
    };
    each_link([&](std::uint32_t a, std::uint32_t b) { ++begin[a + 1], ++begin[b + 1]; });
    for (std::size_t i = 0; i < particles_; ++i) begin[i + 1] += begin[i];
    std::vector<std::uint32_t> all(begin.back());
    std::vector<std::uint32_t> fill(begin.begin(), begin.end() - 1);
    each_link([&](std::uint32_t a, std::uint32_t b) { all[fill[a]++] = b, all[fill[b]++] = a; });
    neighbour_begin_.assign(particles_ + 1, 0);
    neighbour_.clear();
    neighbour_.reserve(all.size());
    for (std::size_t i = 0; i < particles_; ++i) {
        const auto first = all.begin() + begin[i], last = all.begin() + begin[i + 1];
        std::sort(first, last);
        neighbour_.insert(neighbour_.end(), first, std::unique(first, last));
        neighbour_begin_[i + 1] = static_cast<std::uint32_t>(neighbour_.size());
    }
}

bool SelfCollision::neighbours(std::uint32_t i, std::uint32_t j) const {
    const auto begin = neighbour_.begin() + neighbour_begin_[i], end = neighbour_.begin() + neighbour_begin_[i + 1];
    return std::binary_search(begin, end, j);
}

double SelfCollision::contact_distance(const CollisionSettings& settings) const {
    return std::max(static_cast<double>(settings.self_thickness), spacing_);
}

bool SelfCollision::adjacent_tiles(std::uint32_t a, std::uint32_t b) const {
    return std::abs(tile_row_[a] - tile_row_[b]) <= 1 && std::abs(tile_col_[a] - tile_col_[b]) <= 1;
}

// The box of every tile's present particles (NaN coordinates and absent grid slots left out).
void SelfCollision::tile_boxes(const DVec3Array& position) {
    boxes_.assign(static_cast<std::size_t>(tile_rows_) * tile_cols_, Box{});
    auto add = [&](Box& box, std::size_t i) {
        const glm::vec3 p(static_cast<float>(position.x[i]), static_cast<float>(position.y[i]),
                          static_cast<float>(position.z[i]));
        box.lo = glm::min(box.lo, p);  // glm::min(a, NaN) keeps a
        box.hi = glm::max(box.hi, p);
    };
    if (!grid_) {
        for (std::size_t i = 0; i < particles_; ++i) add(boxes_[i / kSelfTileParticles], i);
        return;
    }
    for (int r = 0; r < rows_; ++r) {
        Box* row_tiles = boxes_.data() + static_cast<std::size_t>(r / kSelfTile) * tile_cols_;
        const std::size_t first = static_cast<std::size_t>(r) * cols_;
        for (int c = 0; c < cols_; ++c) add(row_tiles[c / kSelfTile], first + c);
    }
}

std::size_t SelfCollision::mark_active(float reach) {
    // Regions whose box diagonal falls below this fraction of the rest diagonal count as folded.
    constexpr float kCrumpled = 0.9f;
    const std::size_t tiles = boxes_.size();
    // Insertion sort by lo.x from the last substep's order: nearly sorted already, so nearly linear.
    for (std::size_t k = 1; k < tiles; ++k) {
        const std::uint32_t t = order_[k];
        const float key = boxes_[t].lo.x;
        std::size_t j = k;
        for (; j > 0 && boxes_[order_[j - 1]].lo.x > key; --j) order_[j] = order_[j - 1];
        order_[j] = t;
    }
    active_.assign(tiles, 0);
    tile_pairs_.clear();
    for (std::size_t k = 0; k < tiles; ++k) {
        const std::uint32_t a = order_[k];
        if (boxes_[a].empty()) continue;
        for (std::size_t m = k + 1; m < tiles; ++m) {
            const std::uint32_t b = order_[m];
            if (boxes_[b].lo.x > boxes_[a].hi.x + reach) break;
            if (!within(boxes_[a], boxes_[b], reach) || adjacent_tiles(a, b)) continue;
            active_[a] = active_[b] = 1;
            tile_pairs_.push_back(pair_key(a, b));
        }
    }
    // A fold within a tile or between grid neighbours shrinks their box below its rest diagonal (the box's
    // diagonal is at least the distance between any two of its particles): such tiles are marked too.
    // Looking ahead (reach > d) the test allows the shrinking the extra reach could bring.
    if (grid_) {
        const float slack = reach - d_for_reach_;
        auto box_diagonal = [](const Box& b) { return glm::length(b.hi - b.lo); };
        auto joined = [](const Box& a, const Box& b) { return Box{glm::min(a.lo, b.lo), glm::max(a.hi, b.hi)}; };
        for (int r = 0; r < tile_rows_; ++r) {
            for (int c = 0; c < tile_cols_; ++c) {
                const std::uint32_t t = static_cast<std::uint32_t>(r * tile_cols_ + c);
                const float* rest = tile_rest_.data() + static_cast<std::size_t>(t) * 5;
                auto crumpled = [&](const Box& box, float rest_diagonal) {
                    return !box.empty() && box_diagonal(box) < kCrumpled * rest_diagonal + slack;
                };
                if (crumpled(boxes_[t], rest[0])) active_[t] = 1;
                const int dr[5] = {0, 0, 1, 1, 1}, dc[5] = {0, 1, 0, 1, -1};
                for (int k = 1; k < 5; ++k) {
                    if (rest[k] == 0.0f) continue;
                    const std::uint32_t u = static_cast<std::uint32_t>((r + dr[k]) * tile_cols_ + (c + dc[k]));
                    if (crumpled(joined(boxes_[t], boxes_[u]), rest[k])) active_[t] = active_[u] = 1;
                }
            }
        }
    }
    if (std::find(active_.begin(), active_.end(), std::uint8_t{1}) == active_.end()) return 0;
    // A fold that brings two far tiles together turns in the tiles between: an active tile is also tested
    // against itself and its grid neighbours.
    std::size_t count = 0;
    for (std::uint32_t t = 0; t < tiles; ++t) {
        if (!active_[t]) continue;
        ++count;
        const int r = static_cast<int>(t) / tile_cols_, c = static_cast<int>(t) % tile_cols_;
        for (int dr = -1; dr <= 1; ++dr) {
            for (int dc = -1; dc <= 1; ++dc) {
                if (r + dr < 0 || r + dr >= tile_rows_ || c + dc < 0 || c + dc >= tile_cols_) continue;
                tile_pairs_.push_back(pair_key(t, static_cast<std::uint32_t>((r + dr) * tile_cols_ + (c + dc))));
            }
        }
    }
    std::sort(tile_pairs_.begin(), tile_pairs_.end());
    tile_pairs_.erase(std::unique(tile_pairs_.begin(), tile_pairs_.end()), tile_pairs_.end());
    return count;
}

// The present particles of tile t, in index order.
void SelfCollision::tile_particles(std::uint32_t t, const State& state, std::vector<std::uint32_t>& out) const {
    out.clear();
    auto add = [&](std::size_t i) {
        if (state.pinned[i] != kAbsent) out.push_back(static_cast<std::uint32_t>(i));
    };
    if (!grid_) {
        const std::size_t begin = static_cast<std::size_t>(t) * kSelfTileParticles;
        for (std::size_t i = begin; i < std::min(particles_, begin + kSelfTileParticles); ++i) add(i);
        return;
    }
    const int r0 = static_cast<int>(t) / tile_cols_ * kSelfTile, c0 = static_cast<int>(t) % tile_cols_ * kSelfTile;
    for (int r = r0; r < std::min(rows_, r0 + kSelfTile); ++r) {
        for (int c = c0; c < std::min(cols_, c0 + kSelfTile); ++c) add(static_cast<std::size_t>(r) * cols_ + c);
    }
}

SelfCollisionCounts SelfCollision::collide(State& state, const CollisionSettings& settings,
                                           const DVec3Array& rest_position) {
    SelfCollisionCounts counts;
    const double d = contact_distance(settings);
    if (!(d > 0.0) || particles_ != state.size()) return counts;
    const std::size_t n = particles_;

    // No particle moves more than d / 4 in a substep: two layers close by at most d / 2 between checks.
    const double longest = 0.25 * d, longest2 = longest * longest;
    double fastest2 = 0.0;  // a vectorised pass finds whether any particle needs the clamp
    for (std::size_t i = 0; i < n; ++i) {
        const double mx = state.motion.x[i], my = state.motion.y[i], mz = state.motion.z[i];
        fastest2 = std::max(fastest2, mx * mx + my * my + mz * mz);
    }
    for (std::size_t i = 0; i < n && fastest2 > longest2; ++i) {
        const double mx = state.motion.x[i], my = state.motion.y[i], mz = state.motion.z[i];
        const double m2 = mx * mx + my * my + mz * mz;
        if (!(m2 > longest2)) continue;  // also NaN: left to the guard
        const glm::dvec3 m(mx, my, mz);
        const glm::dvec3 clamped = m * (longest / std::sqrt(m2));
        state.position.add(i, clamped - m);
        state.motion.set(i, clamped);
        ++counts.clamped;
    }

    // The box test. After one that found no tiles within reach of each other, the next kSelfSkip - 1
    // substeps need none: tested with reach d + (kSelfSkip - 1) d / 2, no two far tiles can have come
    // within d since (each substep closes at most d / 2).
    if (substeps_to_test_ > 0 && tested_distance_ == d) {
        --substeps_to_test_;
        return counts;
    }
    tile_boxes(state.position);
    counts.tiles = static_cast<long long>(boxes_.size());
    const double reach = d + 0.5 * (kSelfSkip - 1) * d;
    d_for_reach_ = static_cast<float>(d);
    if (mark_active(static_cast<float>(reach)) == 0) {
        substeps_to_test_ = kSelfSkip - 1;
        tested_distance_ = d;
        return counts;
    }
    counts.tiles_active = static_cast<long long>(mark_active(static_cast<float>(d)));
    if (counts.tiles_active == 0) return counts;

    // Candidate pairs: within d at the current positions, from each tile pair once (so each particle pair at
    // most once), then resolved in (i, j) order whatever order the tiles came in.
    const double d2 = d * d;
    candidates_.clear();
    for (const std::uint64_t key : tile_pairs_) {
        const auto a = static_cast<std::uint32_t>(key >> 32), b = static_cast<std::uint32_t>(key);
        tile_particles(a, state, first_);
        tile_particles(b, state, second_);
        for (std::size_t u = 0; u < first_.size(); ++u) {
            const std::uint32_t i = first_[u];
            const double px = state.position.x[i], py = state.position.y[i], pz = state.position.z[i];
            for (std::size_t v = a == b ? u + 1 : 0; v < second_.size(); ++v) {
                const std::uint32_t j = second_[v];
                const double vx = state.position.x[j] - px, vy = state.position.y[j] - py, vz = state.position.z[j] - pz;
                if (vx * vx + vy * vy + vz * vz < d2 && !neighbours(i, j)) candidates_.push_back(pair_key(i, j));
            }
        }
    }
    std::sort(candidates_.begin(), candidates_.end());

    for (const std::uint64_t key : candidates_) {
        const auto i = static_cast<std::uint32_t>(key >> 32), j = static_cast<std::uint32_t>(key);
        const double wi = state.inverse_mass[i], wj = state.inverse_mass[j], w = wi + wj;
        if (w == 0.0) continue;
        const double rest = glm::length(rest_position.get(j) - rest_position.get(i));
        const double least = std::min(d, rest);
        const glm::dvec3 v = state.position.get(j) - state.position.get(i);
        const double length = glm::length(v);
        if (!(length < least)) continue;
        // Coincident particles part along their rest direction (any fixed direction would do).
        const glm::dvec3 normal = length > 1e-12 * least ? v / length
                                                         : glm::normalize(rest_position.get(j) - rest_position.get(i));
        const double push = least - length;
        state.position.add(i, -(wi / w) * push * normal);
        state.position.add(j, (wj / w) * push * normal);
        // Inelastic: the approach along the normal goes; friction slows the sliding by at most mu x push
        // (the push is the contact's normal displacement this substep).
        glm::dvec3 relative = state.motion.get(j) - state.motion.get(i);
        const double approach = glm::dot(relative, normal);
        glm::dvec3 change(0.0);
        if (approach < 0.0) change += approach * normal;
        relative -= change;
        const glm::dvec3 sliding = relative - glm::dot(relative, normal) * normal;
        const double slide = glm::length(sliding);
        const double grip = static_cast<double>(settings.self_friction) * push;
        if (slide > 0.0) change += sliding * std::min(1.0, grip / slide);
        state.motion.add(i, (wi / w) * change);
        state.motion.add(j, -(wj / w) * change);
        ++counts.contacts;
    }
    return counts;
}

}  // namespace clothsim
