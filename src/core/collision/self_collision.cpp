#include "collision/self_collision.hpp"

#include <glm/geometric.hpp>

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clothsim {
namespace {

constexpr std::uint32_t kSelfTileParticles = kSelfTile * kSelfTile;

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | b;
}

// Twice the vector area of the quadrilateral of a tile's corners (00, 0c, r0, rc): the cross product of its
// diagonals. Its direction is the tile's mean normal; a tile folded onto itself has almost none left.
glm::dvec3 vector_area(const DVec3Array& position, const std::array<std::uint32_t, 4>& corner) {
    return glm::cross(position.get(corner[3]) - position.get(corner[0]), position.get(corner[1]) - position.get(corner[2]));
}

// The Euclidean gap between boxes a and b (0 when they overlap): no point of one is nearer the other.
float box_gap(const Box& a, const Box& b) {
    const glm::vec3 gap = glm::max(glm::max(b.lo - a.hi, a.lo - b.hi), glm::vec3(0.0f));
    return glm::length(gap);
}

// The skin of a fold pair kept `kept` apart: at most half its kept distance, so that a straight cloth's fold
// pairs (2 s apart) are not listed however thick the cloth.
double fold_skin(double kept, double skin) { return std::min(skin, 0.5 * kept); }

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
    grid_ = !topology.mesh && rows_ > 0 && cols_ > 0 && static_cast<std::size_t>(rows_) * cols_ == particles_;
    spacing_ = particle_spacing(topology);
    update_neighbours(topology, rest_position);
    if (grid_) {
        tile_rows_ = (rows_ + kSelfTile - 1) / kSelfTile;
        tile_cols_ = (cols_ + kSelfTile - 1) / kSelfTile;
    } else {
        grow_patches();
        tile_rows_ = 1;
        tile_cols_ = static_cast<int>(member_begin_.size() - 1);
        link_patches();
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
    // Each tile's corner particles and its vector area at rest (the fold test compares against it).
    if (grid_) {
        corner_.resize(tiles);
        rest_area_.resize(tiles);
        for (std::size_t t = 0; t < tiles; ++t) {
            const int r0 = tile_row_[t] * kSelfTile, c0 = tile_col_[t] * kSelfTile;
            const int r1 = std::min(rows_, r0 + kSelfTile) - 1, c1 = std::min(cols_, c0 + kSelfTile) - 1;
            auto at = [&](int r, int c) { return static_cast<std::uint32_t>(static_cast<std::size_t>(r) * cols_ + c); };
            corner_[t] = {at(r0, c0), at(r0, c1), at(r1, c0), at(r1, c1)};
            rest_area_[t] = static_cast<float>(glm::length(vector_area(rest_position, corner_[t])));
        }
        // The rest diagonal of each tile alone and with its neighbours to the right, below, below right and
        // below left: the longer distance between opposite corner particles of the region.
        tile_rest_.assign(tiles * 5, 0.0f);
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
}

void SelfCollision::update_neighbours(const Topology& topology, const DVec3Array& rest_position) {
    tested_distance_ = 0.0;  // pairs that shared a spring may meet now: test at the next substep
    candidates_.clear();
    // Compressed rows: count, fill, then sort and drop repeats within each particle's run.
    std::vector<std::uint32_t> begin(particles_ + 1, 0);
    auto each_link = [&](auto&& link) {
        for (const Spring& s : topology.springs) link(s.a, s.b);
        for (const Bend& b : topology.bends) {
            link(b.a, b.m);
            link(b.m, b.b);
            link(b.a, b.b);
        }
        for (const Hinge& h : topology.hinges) {
            for (const auto& [a, b] : {std::pair{0, 1}, {0, 2}, {1, 2}, {0, 3}, {1, 3}, {2, 3}}) link(h.v[a], h.v[b]);
        }
    };
    each_link([&](std::uint32_t a, std::uint32_t b) { ++begin[a + 1], ++begin[b + 1]; });
    for (std::size_t i = 0; i < particles_; ++i) begin[i + 1] += begin[i];
    std::vector<std::uint32_t> all(begin.back());
    std::vector<std::uint32_t> fill(begin.begin(), begin.end() - 1);
    each_link([&](std::uint32_t a, std::uint32_t b) { all[fill[a]++] = b, all[fill[b]++] = a; });
    // On a grid whose links all span at most two rows and columns, each particle's neighbours also fit a
    // 5 x 5 bit mask, tested without a search.
    far_links_ = false;
    near_mask_.assign(grid_ ? particles_ : 0, 0u);
    if (grid_) {
        each_link([&](std::uint32_t a, std::uint32_t b) {
            const int dr = static_cast<int>(b) / cols_ - static_cast<int>(a) / cols_;
            const int dc = static_cast<int>(b) % cols_ - static_cast<int>(a) % cols_;
            if (std::abs(dr) > 2 || std::abs(dc) > 2) {
                far_links_ = true;
                return;
            }
            near_mask_[a] |= 1u << ((dr + 2) * 5 + (dc + 2));
            near_mask_[b] |= 1u << ((2 - dr) * 5 + (2 - dc));
        });
    }
    neighbour_begin_.assign(particles_ + 1, 0);
    neighbour_.clear();
    neighbour_.reserve(all.size());
    for (std::size_t i = 0; i < particles_; ++i) {
        const auto first = all.begin() + begin[i], last = all.begin() + begin[i + 1];
        std::sort(first, last);
        neighbour_.insert(neighbour_.end(), first, std::unique(first, last));
        neighbour_begin_[i + 1] = static_cast<std::uint32_t>(neighbour_.size());
    }
    // Fold pairs: the ends of a skip-one bending spring or of a bend. Each with kSelfFoldShare of its rest
    // distance, and on the grid the longest at each offset.
    std::vector<std::uint64_t> bending;
    for (const Spring& spring : topology.springs) {
        if (spring.kind == SpringKind::Bending) bending.push_back(pair_key(spring.a, spring.b));
    }
    for (const Bend& b : topology.bends) bending.push_back(pair_key(b.a, b.b));
    for (const Hinge& h : topology.hinges) bending.push_back(pair_key(h.v[2], h.v[3]));
    if (!grid_ || far_links_) {  // fold_pair() searches the list
        std::sort(bending.begin(), bending.end());
        bending.erase(std::unique(bending.begin(), bending.end()), bending.end());
    }
    fold_pairs_.clear();
    fold_kept_rest_.clear();
    fold_mask_.assign(near_mask_.size(), 0u);
    longest_fold_kept_rest_.fill(0.0);
    for (const std::uint64_t key : bending) {
        const auto i = static_cast<std::uint32_t>(key >> 32), j = static_cast<std::uint32_t>(key);
        const double kept_rest = kSelfFoldShare * glm::length(rest_position.get(j) - rest_position.get(i));
        fold_pairs_.push_back(key);
        fold_kept_rest_.push_back(kept_rest);
        if (!grid_ || far_links_) continue;
        const int dr = static_cast<int>(j) / cols_ - static_cast<int>(i) / cols_;
        const int dc = static_cast<int>(j) % cols_ - static_cast<int>(i) % cols_;
        fold_mask_[i] |= 1u << ((dr + 2) * 5 + (dc + 2));
        fold_mask_[j] |= 1u << ((2 - dr) * 5 + (2 - dc));
        for (const int k : {(dr + 2) * 5 + (dc + 2), (2 - dr) * 5 + (2 - dc)}) {
            longest_fold_kept_rest_[k] = std::max(longest_fold_kept_rest_[k], kept_rest);
        }
    }
    // Each neighbour entry's fold share, so one search in a particle's short list tells both.
    neighbour_fold_kept_.assign(neighbour_.size(), 0.0);
    for (std::size_t k = 0; k < fold_pairs_.size(); ++k) {
        const auto i = static_cast<std::uint32_t>(fold_pairs_[k] >> 32), j = static_cast<std::uint32_t>(fold_pairs_[k]);
        for (const auto& [a, b] : {std::pair{i, j}, std::pair{j, i}}) {
            const auto from = neighbour_.begin() + neighbour_begin_[a], to = neighbour_.begin() + neighbour_begin_[a + 1];
            const auto at = std::lower_bound(from, to, b);
            if (at != to && *at == b) neighbour_fold_kept_[static_cast<std::size_t>(at - neighbour_.begin())] = fold_kept_rest_[k];
        }
    }
    if (!grid_ && !particle_tile_.empty()) link_patches();  // a tear changed the links
}

double SelfCollision::link_of(std::uint32_t i, std::uint32_t j) const {
    const auto begin = neighbour_.begin() + neighbour_begin_[i], end = neighbour_.begin() + neighbour_begin_[i + 1];
    const auto at = std::lower_bound(begin, end, j);
    if (at == end || *at != j) return -1.0;
    return neighbour_fold_kept_[static_cast<std::size_t>(at - neighbour_.begin())];
}

void SelfCollision::grow_patches() {
    // Breadth-first from the first particle not yet in a tile, over the links, until the tile is full.
    constexpr std::uint32_t kNone = 0xffffffffu;
    particle_tile_.assign(particles_, kNone);
    member_begin_.assign(1, 0);
    member_.clear();
    member_.reserve(particles_);
    for (std::size_t seed = 0; seed < particles_; ++seed) {
        if (particle_tile_[seed] != kNone) continue;
        const auto tile = static_cast<std::uint32_t>(member_begin_.size() - 1);
        const std::size_t first = member_.size();
        particle_tile_[seed] = tile;
        member_.push_back(static_cast<std::uint32_t>(seed));
        for (std::size_t head = first; head < member_.size() && member_.size() - first < kSelfTileParticles; ++head) {
            const std::uint32_t i = member_[head];
            for (std::uint32_t k = neighbour_begin_[i]; k < neighbour_begin_[i + 1]; ++k) {
                const std::uint32_t j = neighbour_[k];
                if (particle_tile_[j] != kNone || member_.size() - first >= kSelfTileParticles) continue;
                particle_tile_[j] = tile;
                member_.push_back(j);
            }
        }
        member_begin_.push_back(static_cast<std::uint32_t>(member_.size()));
    }
}

void SelfCollision::link_patches() {
    // Neighbour patches: joined by a link (a spring, a bend, a hinge's pair).
    const std::size_t tiles = member_begin_.size() - 1;
    std::vector<std::vector<std::uint32_t>> joined(tiles);
    for (std::size_t i = 0; i < particles_; ++i) {
        for (std::uint32_t k = neighbour_begin_[i]; k < neighbour_begin_[i + 1]; ++k) {
            const std::uint32_t a = particle_tile_[i], b = particle_tile_[neighbour_[k]];
            if (a != b) joined[a].push_back(b);
        }
    }
    tile_link_begin_.assign(1, 0);
    tile_link_.clear();
    for (std::uint32_t t = 0; t < tiles; ++t) {
        std::sort(joined[t].begin(), joined[t].end());
        tile_link_.insert(tile_link_.end(), joined[t].begin(), std::unique(joined[t].begin(), joined[t].end()));
        tile_link_begin_.push_back(static_cast<std::uint32_t>(tile_link_.size()));
    }
}

bool SelfCollision::neighbours(std::uint32_t i, std::uint32_t j) const {
    if (grid_ && !far_links_) {
        const int dr = static_cast<int>(j) / cols_ - static_cast<int>(i) / cols_;
        const int dc = static_cast<int>(j) % cols_ - static_cast<int>(i) % cols_;
        return near_neighbours(i, dr, dc);
    }
    return link_of(i, j) >= 0.0;
}

bool SelfCollision::fold_pair(std::uint32_t i, std::uint32_t j) const {
    if (grid_ && !far_links_) {
        const int dr = static_cast<int>(j) / cols_ - static_cast<int>(i) / cols_;
        const int dc = static_cast<int>(j) % cols_ - static_cast<int>(i) % cols_;
        return near_fold_pair(i, dr, dc);
    }
    return std::binary_search(fold_pairs_.begin(), fold_pairs_.end(), pair_key(i, j));
}

double SelfCollision::kept_distance(std::uint32_t i, std::uint32_t j, double d, const DVec3Array& rest_position) const {
    if (!grid_ || far_links_) {
        const double link = link_of(i, j);
        if (link >= 0.0) return link > 0.0 ? std::min(d, link) : 0.0;
        return std::min(d, glm::length(rest_position.get(j) - rest_position.get(i)));
    }
    const double rest = glm::length(rest_position.get(j) - rest_position.get(i));
    if (fold_pair(i, j)) return std::min(d, kSelfFoldShare * rest);
    return neighbours(i, j) ? 0.0 : std::min(d, rest);
}

double SelfCollision::contact_distance(const CollisionSettings& settings) const {
    return std::max(static_cast<double>(settings.self_thickness), spacing_);
}

std::uint32_t SelfCollision::tile_of(std::uint32_t i) const {
    if (!grid_) return particle_tile_[i];
    const int r = static_cast<int>(i) / cols_, c = static_cast<int>(i) % cols_;
    return static_cast<std::uint32_t>((r / kSelfTile) * tile_cols_ + c / kSelfTile);
}

bool SelfCollision::adjacent_tiles(std::uint32_t a, std::uint32_t b) const {
    if (!grid_) {
        return a == b || std::binary_search(tile_link_.begin() + tile_link_begin_[a], tile_link_.begin() + tile_link_begin_[a + 1], b);
    }
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
        for (std::size_t t = 0; t + 1 < member_begin_.size(); ++t) {
            for (std::uint32_t k = member_begin_[t]; k < member_begin_[t + 1]; ++k) add(boxes_[t], member_[k]);
        }
        return;
    }
    for (int r = 0; r < rows_; ++r) {
        Box* row_tiles = boxes_.data() + static_cast<std::size_t>(r / kSelfTile) * tile_cols_;
        const std::size_t first = static_cast<std::size_t>(r) * cols_;
        for (int c = 0; c < cols_; ++c) add(row_tiles[c / kSelfTile], first + c);
    }
}

// The box test, the fold test and the narrow phase's tile pairs (see the header), and `budget`: how far any
// two particles may close in before the next test is needed (0: test again at the next substep).
std::size_t SelfCollision::mark_active(const DVec3Array& position, float d, float skin, float reach, double& budget) {
    constexpr float kCrumpled = 0.8f;  // box diagonal over rest diagonal below which a region counts as folded
    // Neighbours whose mean normals are more than 60 degrees apart go to the narrow phase. Only a hairpin
    // (more than 90) can meet itself, but a pair bent near 90 degrees (over a cube's edge) would leave the
    // others almost no budget (the cosine's distance to 0, below).
    constexpr float kBent = 0.5f;
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
    // The sweep: `visit(a, b)` for every pair of tiles that are not grid neighbours and whose boxes come
    // within `within_reach` of each other per axis.
    auto far_pairs = [&](float within_reach, const auto& visit) {
        for (std::size_t k = 0; k < tiles; ++k) {
            const std::uint32_t a = order_[k];
            if (boxes_[a].empty()) continue;
            for (std::size_t m = k + 1; m < tiles; ++m) {
                const std::uint32_t b = order_[m];
                if (boxes_[b].lo.x > boxes_[a].hi.x + within_reach) break;
                if (within(boxes_[a], boxes_[b], within_reach) && !adjacent_tiles(a, b)) visit(a, b);
            }
        }
    };
    // Far pairs within d + skin of each other.
    far_pairs(d + skin, [&](std::uint32_t a, std::uint32_t b) {
        active_[a] = active_[b] = 1;
        tile_pairs_.push_back(pair_key(a, b));
    });
    // Folds within a tile or between grid neighbours (Volino & Magnenat-Thalmann 1994: a surface whose
    // normals all lie within a half-space cannot meet itself). A tile is folded when its vector area falls
    // under half its rest area, two neighbours when their mean normals point apart (a hairpin). Such
    // tiles are tested against themselves and their neighbours.
    // Crumpled regions: a tile, or a tile with a neighbour, whose box diagonal (at least the distance
    // between any two of its particles) falls under 0.8 of its rest diagonal (a fold or an accordion
    // buckle across tiles that leaves each tile's normal alone).
    auto box_diagonal = [](const Box& b) { return glm::length(b.hi - b.lo); };
    auto joined = [](const Box& a, const Box& b) { return Box{glm::min(a.lo, b.lo), glm::max(a.hi, b.hi)}; };
    static constexpr int kDr[5] = {0, 0, 1, 1, 1}, kDc[5] = {0, 1, 0, 1, -1};
    auto neighbour = [&](std::uint32_t t, int k) {
        return static_cast<std::uint32_t>((tile_row_[t] + kDr[k]) * tile_cols_ + (tile_col_[t] + kDc[k]));
    };
    if (grid_) {
        normal_.resize(tiles);
        area_.resize(tiles);
        diagonals_.resize(tiles);
        for (std::size_t t = 0; t < tiles; ++t) {
            const std::array<std::uint32_t, 4>& corner = corner_[t];
            const glm::dvec3 d1 = position.get(corner[3]) - position.get(corner[0]);
            const glm::dvec3 d2 = position.get(corner[1]) - position.get(corner[2]);
            const glm::dvec3 area = glm::cross(d1, d2);
            const double length = glm::length(area);
            area_[t] = length;
            diagonals_[t] = glm::length(d1) + glm::length(d2);
            normal_[t] = length > 0.0 ? glm::vec3(area / length) : glm::vec3(0.0f);
            if (!(length >= 0.5 * rest_area_[t])) active_[t] = 2;  // also NaN
        }
        for (std::uint32_t t = 0; t < tiles; ++t) {
            const float* rest = tile_rest_.data() + static_cast<std::size_t>(t) * 5;
            if (!boxes_[t].empty() && box_diagonal(boxes_[t]) < kCrumpled * rest[0]) active_[t] = 2;
            for (int k = 1; k < 5; ++k) {
                if (rest[k] == 0.0f) continue;
                const std::uint32_t u = neighbour(t, k);
                if (!(glm::dot(normal_[t], normal_[u]) >= kBent)) active_[t] = active_[u] = 2;
                if (boxes_[t].empty() || boxes_[u].empty()) continue;
                if (box_diagonal(joined(boxes_[t], boxes_[u])) < kCrumpled * rest[k]) active_[t] = active_[u] = 2;
            }
        }
    }
    // Fold pairs near their kept distance (a crease sharper than a tile, which the thresholds above do not
    // see): the tiles of both go to the narrow phase. The others' margins bound the budget below: a
    // distance shrinks by at most the closing.
    double fold_margin = std::numeric_limits<double>::infinity();
    double least_fold_skin = std::numeric_limits<double>::infinity();  // bounds the budget when listing
    // (Off the grid every patch is in the narrow phase and a fold pair is listed out to its kept distance plus
    // the whole skin: the skin alone bounds the budget.)
    for (std::size_t k = 0; grid_ && k < fold_pairs_.size(); ++k) {
        const auto i = static_cast<std::uint32_t>(fold_pairs_[k] >> 32), j = static_cast<std::uint32_t>(fold_pairs_[k]);
        const double kept = std::min(double(d), fold_kept_rest_[k]);
        const double margin = glm::length(position.get(j) - position.get(i)) - kept;
        least_fold_skin = std::min(least_fold_skin, fold_skin(kept, skin));
        if (margin >= fold_skin(kept, skin)) {
            fold_margin = std::min(fold_margin, margin);
        } else {  // also NaN
            active_[tile_of(i)] = active_[tile_of(j)] = 2;
        }
    }
    // Off the grid every patch goes to the narrow phase with itself and its neighbour patches: a patch has the
    // mesh's shape, not a square of the grid's, so its box and vector area cannot tell when it is folded or
    // squeezed (an accordion buckle within one patch keeps more than half its vector area). Only far patches
    // are left to the sweep.
    for (std::uint32_t t = 0; !grid_ && t < tiles; ++t) {
        if (active_[t] == 0) active_[t] = 1;
        tile_pairs_.push_back(pair_key(t, t));
        for (std::uint32_t k = tile_link_begin_[t]; k < tile_link_begin_[t + 1]; ++k) {
            if (tile_link_[k] > t) tile_pairs_.push_back(pair_key(t, tile_link_[k]));
        }
    }
    const bool any_active = std::find_if(active_.begin(), active_.end(), [](std::uint8_t a) { return a != 0; }) != active_.end();
    // The budget: how much any two particles may close in before a test could find something new. When no
    // two particles close in by more than b, far boxes come b nearer at most, a diagonal shrinks by at most
    // b, a vector area (the cross product of the diagonals D1, D2) by at most b (|D1| + |D2|), and a mean
    // normal turns by at most 2 b (|D1| + |D2|) / |area| radians (to first order); two normals with cosine c
    // are at least asin(c) >= c radians from being 90 degrees apart. With tiles in the narrow phase, their
    // pairs are listed out to d + skin, so the skin bounds it, and the fold thresholds of the tiles and
    // neighbour pairs not in the narrow phase yet.
    budget = std::min(any_active ? std::min(double(skin), least_fold_skin) : double(reach - d), fold_margin);
    for (std::uint32_t t = 0; grid_ && t < tiles; ++t) {
        const float* rest = tile_rest_.data() + static_cast<std::size_t>(t) * 5;
        if (active_[t] != 2) {
            budget = std::min(budget, (area_[t] - 0.5 * rest_area_[t]) / diagonals_[t]);
            if (!boxes_[t].empty()) budget = std::min(budget, static_cast<double>(box_diagonal(boxes_[t]) - kCrumpled * rest[0]));
        }
        const double turn_t = 2.0 * diagonals_[t] / area_[t];
        for (int k = 1; k < 5; ++k) {
            if (rest[k] == 0.0f) continue;
            const std::uint32_t u = neighbour(t, k);
            if (active_[t] == 2 || active_[u] == 2) continue;  // their pair is in the narrow phase
            const double cosine = glm::dot(normal_[t], normal_[u]);
            budget = std::min(budget, cosine / (turn_t + 2.0 * diagonals_[u] / area_[u]));
            if (boxes_[t].empty() || boxes_[u].empty()) continue;
            budget = std::min(budget, static_cast<double>(box_diagonal(joined(boxes_[t], boxes_[u])) - kCrumpled * rest[k]));
        }
    }
    if (!any_active) {
        // Far boxes need be looked for only out to d + the budget the folds leave: a nearer gap lowers it.
        if (budget > 0.0) {
            far_pairs(static_cast<float>(d + budget), [&](std::uint32_t a, std::uint32_t b) {
                budget = std::min(budget, static_cast<double>(box_gap(boxes_[a], boxes_[b])) - d);
            });
        }
        if (!(budget > 0.0)) budget = 0.0;  // also NaN
        return 0;
    }
    if (!(budget > 0.0)) budget = 0.0;
    std::size_t count = 0;
    for (std::uint32_t t = 0; t < tiles; ++t) {
        if (active_[t] == 0) continue;
        ++count;
        if (active_[t] != 2) continue;  // (never 2 off the grid: every patch is listed above, with its neighbours)
        const int r = tile_row_[t], c = tile_col_[t];
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

// Tile t's present particles as float coordinates, padded to kSelfTileParticles with far-away points.
void SelfCollision::gather(std::uint32_t t, const State& state, TilePoints& out) const {
    int n = 0;
    auto add = [&](std::size_t i) {
        if (state.pinned[i] == kAbsent) return;
        out.index[n] = static_cast<std::uint32_t>(i);
        out.row[n] = grid_ ? static_cast<int>(i) / cols_ : 0;
        out.col[n] = grid_ ? static_cast<int>(i) % cols_ : 0;
        out.x[n] = static_cast<float>(state.position.x[i]);
        out.y[n] = static_cast<float>(state.position.y[i]);
        out.z[n] = static_cast<float>(state.position.z[i]);
        ++n;
    };
    if (!grid_) {
        for (std::uint32_t k = member_begin_[t]; k < member_begin_[t + 1]; ++k) add(member_[k]);
    } else {
        const int r0 = tile_row_[t] * kSelfTile, c0 = tile_col_[t] * kSelfTile;
        for (int r = r0; r < std::min(rows_, r0 + kSelfTile); ++r) {
            for (int c = c0; c < std::min(cols_, c0 + kSelfTile); ++c) add(static_cast<std::size_t>(r) * cols_ + c);
        }
    }
    out.count = n;
    for (; n < static_cast<int>(kSelfTileParticles); ++n) {
        out.index[n] = 0;
        out.x[n] = out.y[n] = out.z[n] = 1e30f;  // its squared distance to anything is inf: never a candidate
    }
}

SelfCollisionCounts SelfCollision::collide(State& state, const CollisionSettings& settings,
                                           const DVec3Array& rest_position, const MotionBounds* known,
                                           bool uncounted) {
    SelfCollisionCounts counts;
    const double d = contact_distance(settings);
    if (!(d > 0.0) || particles_ != state.size()) return counts;
    const std::size_t n = particles_;

    // No particle moves more than d / 4 in a substep: two layers close by at most d / 2 between checks.
    const double longest = 0.25 * d, longest2 = longest * longest;
    // The fast solver's sweep leaves them when nothing moved a particle since: then no pass is needed here.
    MotionBounds range;
    if (known) {
        range = *known;
    } else {
        include_motion(state.motion, 0, n, range);  // one vectorised pass
    }
    bool clamped = false;
    for (std::size_t i = 0; i < n && !(range.largest() <= longest); ++i) {
        const double mx = state.motion.x[i], my = state.motion.y[i], mz = state.motion.z[i];
        const double m2 = mx * mx + my * my + mz * mz;
        if (!(m2 > longest2)) continue;  // also NaN: left to the guard
        const glm::dvec3 m(mx, my, mz);
        const glm::dvec3 limited = m * (longest / std::sqrt(m2));
        state.position.add(i, limited - m);
        state.motion.set(i, limited);
        ++counts.clamped;
        clamped = true;
    }

    // Conservative advancement: since the last test, no two particles closed in by more than the sum of
    // these spreads of motions (and of the pushes below), and the test left room for `budget_` of it. Until
    // it is spent, the particle pairs it listed (all within d + skin then) are the only ones that can touch.
    const double skin = kSelfSkin * d;
    if (tested_distance_ == d && !clamped && skipped_ < kSelfSkipLimit &&
        skipped_uncounted_ + (uncounted ? 1 : 0) <= kSelfSkipMax) {
        budget_ -= range.spread();
        if (budget_ > 0.0) {
            ++skipped_;
            if (uncounted) ++skipped_uncounted_;
            counts.tiles_active = listed_tiles_;
            resolve(state, settings, rest_position, counts);
            return counts;
        }
    }
    tile_boxes(state.position);
    counts.tiles = static_cast<long long>(boxes_.size());
    double budget = 0.0;
    const std::size_t marked = mark_active(state.position, static_cast<float>(d), static_cast<float>(skin),
                                           static_cast<float>((1.0 + kSelfLookAhead) * d), budget);
    budget_ = budget;
    skipped_ = skipped_uncounted_ = 0;
    tested_distance_ = d;
    candidates_.clear();
    listed_tiles_ = 0;
    if (marked == 0 || tile_pairs_.empty()) return counts;

    // Candidate pairs: within d + skin (in float, with a margin; the double test in resolve decides) from each
    // tile pair once, so each particle pair at most once; resolved in (i, j) order whatever order the tiles
    // came in.
    const float reach2 = static_cast<float>(1.001 * (d + skin) * (d + skin));
    // A fold pair is listed within its kept distance plus its skin (fold_skin).
    std::array<float, 25> fold_reach2;
    for (std::size_t k = 0; k < fold_reach2.size(); ++k) {
        const double kept = std::min(d, longest_fold_kept_rest_[k]);
        const double reach = kept + fold_skin(kept, skin);
        fold_reach2[k] = static_cast<float>(1.001 * reach * reach);
    }
    points_.resize(boxes_.size());
    gathered_.assign(boxes_.size(), 0);
    for (const std::uint64_t key : tile_pairs_) {
        const auto a = static_cast<std::uint32_t>(key >> 32), b = static_cast<std::uint32_t>(key);
        for (const std::uint32_t t : {a, b}) {
            if (!gathered_[t]) gather(t, state, points_[t]), gathered_[t] = 1;
        }
        const TilePoints& A = points_[a];
        const TilePoints& B = points_[b];
        for (int u = 0; u < A.count; ++u) {
            // Squared distances from A's particle u to all of B's, four at a time (SSE2, the x86-64 baseline).
            const __m128 px = _mm_set1_ps(A.x[u]), py = _mm_set1_ps(A.y[u]), pz = _mm_set1_ps(A.z[u]);
            const __m128 limit = _mm_set1_ps(reach2);
            unsigned close = 0;
            for (int v = 0; v < static_cast<int>(kSelfTileParticles); v += 4) {
                const __m128 dx = _mm_sub_ps(_mm_loadu_ps(B.x + v), px);
                const __m128 dy = _mm_sub_ps(_mm_loadu_ps(B.y + v), py);
                const __m128 dz = _mm_sub_ps(_mm_loadu_ps(B.z + v), pz);
                const __m128 r2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
                close |= static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(r2, limit))) << v;
            }
            if (a == b) close &= ~((2u << u) - 1u);  // within one tile: each pair once, not with itself
            while (close != 0) {
                const int v = __builtin_ctz(close);
                close &= close - 1;
                const std::uint32_t i = A.index[u], j = B.index[v];
                if (grid_ && !far_links_) {
                    const int dr = B.row[v] - A.row[u], dc = B.col[v] - A.col[u];
                    if (near_neighbours(i, dr, dc)) {
                        if (!near_fold_pair(i, dr, dc)) continue;
                        const float x = B.x[v] - A.x[u], y = B.y[v] - A.y[u], z = B.z[v] - A.z[u];
                        if (!(x * x + y * y + z * z < fold_reach2[(dr + 2) * 5 + (dc + 2)])) continue;
                    }
                } else {
                    const double fold_kept = link_of(i, j);
                    if (fold_kept == 0.0) continue;  // neighbours
                    if (fold_kept > 0.0) {  // a fold pair: listed within its kept distance plus its skin (all of it off the grid)
                        const double kept = std::min(d, fold_kept), reach = kept + (grid_ ? fold_skin(kept, skin) : skin);
                        const float x = B.x[v] - A.x[u], y = B.y[v] - A.y[u], z = B.z[v] - A.z[u];
                        if (!(x * x + y * y + z * z < static_cast<float>(1.001 * reach * reach))) continue;
                    }
                }
                candidates_.push_back(pair_key(i, j));
            }
        }
    }
    std::sort(candidates_.begin(), candidates_.end());
    candidate_kept_.resize(candidates_.size());
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
        const std::uint64_t key = candidates_[k];
        candidate_kept_[k] = kept_distance(static_cast<std::uint32_t>(key >> 32), static_cast<std::uint32_t>(key), d, rest_position);
    }
    listed_tiles_ = static_cast<long long>(std::count(gathered_.begin(), gathered_.end(), std::uint8_t{1}));
    counts.tiles_active = listed_tiles_;
    resolve(state, settings, rest_position, counts);
    return counts;
}

// The listed pairs closer than their kept distance, pushed apart in (i, j) order. The pushes move
// particles outside their motion: any two particles may close in by the sum of the distances each was
// pushed, which comes off the budget (twice the largest).
void SelfCollision::resolve(State& state, const CollisionSettings& settings, const DVec3Array& rest_position,
                            SelfCollisionCounts& counts) {
    pushed_.resize(particles_, 0.0);
    pushed_list_.clear();
    auto moved = [&](std::uint32_t p, double distance) {
        if (pushed_[p] == 0.0) pushed_list_.push_back(p);
        pushed_[p] += distance;
    };
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
        const auto i = static_cast<std::uint32_t>(candidates_[k] >> 32), j = static_cast<std::uint32_t>(candidates_[k]);
        const double least = candidate_kept_[k];
        const glm::dvec3 v = state.position.get(j) - state.position.get(i);
        const double length2 = glm::dot(v, v);
        if (!(length2 < least * least)) continue;
        const double wi = state.inverse_mass[i], wj = state.inverse_mass[j], w = wi + wj;
        if (w == 0.0) continue;
        const double length = std::sqrt(length2);
        // Coincident particles part along their rest direction (any fixed direction would do).
        const glm::dvec3 normal = length > 1e-12 * least ? v / length
                                                         : glm::normalize(rest_position.get(j) - rest_position.get(i));
        const double push = least - length;
        state.position.add(i, -(wi / w) * push * normal);
        state.position.add(j, (wj / w) * push * normal);
        moved(i, (wi / w) * push);
        moved(j, (wj / w) * push);
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
    double largest = 0.0;
    for (const std::uint32_t p : pushed_list_) {
        largest = std::max(largest, pushed_[p]);
        pushed_[p] = 0.0;
    }
    budget_ -= 2.0 * largest;
}

}  // namespace clothsim
