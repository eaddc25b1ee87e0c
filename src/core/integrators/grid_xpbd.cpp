#include "integrators/grid_xpbd.hpp"

#include "integrators/fast_solver.hpp"
#include "integrators/work_team.hpp"
#include "model/forces.hpp"

#include <algorithm>
#include <chrono>

#include <cmath>
#include <limits>

namespace clothsim {
namespace {

struct Direction {
    int dr, dc;
};
// fast_solver.cpp's order: structural along and down, the two diagonals, two apart along and down.
constexpr std::array<Direction, 6> kDirections = {{{0, 1}, {1, 0}, {1, 1}, {1, -1}, {0, 2}, {2, 0}}};
constexpr double kInfinite = std::numeric_limits<double>::infinity();

// Where the particles are and how easily they move.
struct Particles {
    double* x;
    double* y;
    double* z;
    const float* w;  // inverse mass, 0 for pinned and absent particles
};

// One batch of springs i -> i + offset for i = first ... last - 1 that share no particle (a row's springs down).
// The arithmetic is step_xpbd's: d = x_b - x_a, |d| = sqrt((dx dx + dy dy) + dz dz),
// lambda = -(|d| - L0) / ((w_a + w_b) + alpha), g = lambda / |d|, x_a -= w_a g d, x_b += w_b g d; nothing
// for a spring without stiffness (alpha infinite) or whose ends coincide. Returns the sum of C^2.
[[gnu::always_inline]] inline double project_springs(const Particles& p, const float* rest, const double* alpha,
                                                     double* lambda, int first, int last, int offset) {
    double* x = p.x;
    double* y = p.y;
    double* z = p.z;
    const float* w = p.w;
    double violation2 = 0.0;
#pragma omp simd reduction(+ : violation2)
    for (int i = first; i < last; ++i) {
        const int j = i + offset;
        const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
        const double length = std::sqrt((dx * dx + dy * dy) + dz * dz);
        const double c = length - static_cast<double>(rest[i]);
        const double wa = w[i], wb = w[j];
        const double l = -c / ((wa + wb) + alpha[i]);
        const bool ok = (length > 1e-12) & (alpha[i] < kInfinite);
        const double g = ok ? l / length : 0.0;
        lambda[i] = ok ? l : 0.0;
        violation2 += ok ? c * c : 0.0;
        const double ga = -(wa * g), gb = wb * g;
        x[i] += dx * ga;
        y[i] += dy * ga;
        z[i] += dz * ga;
        x[j] += dx * gb;
        y[j] += dy * gb;
        z[j] += dz * gb;
    }
    return violation2;
}

// One batch of bends (i, i + offset, i + 2 offset) that share no particle (a row's bends down), as step_xpbd: c = (x_a - x_m) + (x_b - x_m),
// lambda = c * (-1 / (((w_a + 4 w_m) + w_b) + alpha)), x_a += w_a lambda, x_m += -2 w_m lambda, x_b += w_b lambda.
[[gnu::always_inline]] inline double project_bends(const Particles& p, const double* alpha, double* lx, double* ly,
                                                   double* lz, int first, int last, int offset) {
    double* x = p.x;
    double* y = p.y;
    double* z = p.z;
    const float* w = p.w;
    double violation2 = 0.0;
#pragma omp simd reduction(+ : violation2)
    for (int i = first; i < last; ++i) {
        const int m = i + offset, b = i + 2 * offset;
        const double cx = (x[i] - x[m]) + (x[b] - x[m]);
        const double cy = (y[i] - y[m]) + (y[b] - y[m]);
        const double cz = (z[i] - z[m]) + (z[b] - z[m]);
        const double wa = w[i], wm = w[m], wb = w[b];
        const double s = -1.0 / (((wa + 4.0 * wm) + wb) + alpha[i]);
        const bool ok = alpha[i] < kInfinite;
        violation2 += ok ? (cx * cx + cy * cy) + cz * cz : 0.0;
        const double ax = cx * s, ay = cy * s, az = cz * s;
        lx[i] = ax, ly[i] = ay, lz[i] = az;
        const double wm2 = -2.0 * wm;
        x[i] += wa * ax, y[i] += wa * ay, z[i] += wa * az;
        x[m] += wm2 * ax, y[m] += wm2 * ay, z[m] += wm2 * az;
        x[b] += wb * ax, y[b] += wb * ay, z[b] += wb * az;
    }
    return violation2;
}


// Corrections of one row's elements along the row, before they are added: for the element starting in column
// c, to its first particle at a[c], to its middle one (a bend's) at m[c + 1], to its last at b[c + span].
// Every other entry is 0, so each particle's sum adds one correction and zeros.
struct RowCorrections {
    double *ax, *ay, *az, *mx, *my, *mz, *bx, *by, *bz;
    const int* phase2;  // each column modulo 2, for the phase test of the springs along the row
    const int* phase3;  // ... modulo 3, for the skip-one springs and the bends (a modulo in the loop does not vectorise)
};

// The springs along row `row` from column c to c + Span whose column is `phase` modulo Span + 1: no two share a
// particle. A projection along a row is a chain, so the row is computed whole (vectorised) with the other
// phases' corrections set to 0, and then added particle by particle. Arithmetic as project_springs.
template <int Span>
[[gnu::always_inline]] inline double project_row_springs(const Particles& p, const float* rest, const double* alpha,
                                                         double* lambda, int row, int cols, int phase,
                                                         const RowCorrections& t) {
    double* x = p.x + row;
    double* y = p.y + row;
    double* z = p.z + row;
    const float* w = p.w + row;
    rest += row, alpha += row, lambda += row;
    const int* column_phase = Span == 1 ? t.phase2 : t.phase3;
    double* ax = t.ax;
    double* ay = t.ay;
    double* az = t.az;
    double* bx = t.bx + Span;
    double* by = t.by + Span;
    double* bz = t.bz + Span;
    double violation2 = 0.0;
    const int n = cols - Span;
#pragma omp simd reduction(+ : violation2)
    for (int c = 0; c < n; ++c) {
        const double dx = x[c + Span] - x[c], dy = y[c + Span] - y[c], dz = z[c + Span] - z[c];
        const double length = std::sqrt((dx * dx + dy * dy) + dz * dz);
        const double e = length - static_cast<double>(rest[c]);
        const double wa = w[c], wb = w[c + Span];
        const double l = -e / ((wa + wb) + alpha[c]);
        const bool mine = column_phase[c] == phase;
        const bool ok = mine & (length > 1e-12) & (alpha[c] < kInfinite);
        const double g = ok ? l / length : 0.0;
        lambda[c] = mine ? (ok ? l : 0.0) : lambda[c];
        violation2 += ok ? e * e : 0.0;
        const double ga = -(wa * g), gb = wb * g;
        ax[c] = dx * ga, ay[c] = dy * ga, az[c] = dz * ga;
        bx[c] = dx * gb, by[c] = dy * gb, bz[c] = dz * gb;
    }
    for (int c = std::max(n, 0); c < cols; ++c) t.ax[c] = t.ay[c] = t.az[c] = 0.0;  // no element starts there
    for (int c = 0; c < std::min(Span, cols); ++c) t.bx[c] = t.by[c] = t.bz[c] = 0.0;  // ... or ends there
#pragma omp simd
    for (int c = 0; c < cols; ++c) {
        x[c] += t.ax[c] + t.bx[c];
        y[c] += t.ay[c] + t.by[c];
        z[c] += t.az[c] + t.bz[c];
    }
    return violation2;
}

// The bends along row `row` (columns c, c + 1, c + 2) whose first column is `phase` modulo 3, as
// project_row_springs; arithmetic as project_bends.
[[gnu::always_inline]] inline double project_row_bends(const Particles& p, const double* alpha, double* lx, double* ly,
                                                       double* lz, int row, int cols, int phase, const RowCorrections& t) {
    double* x = p.x + row;
    double* y = p.y + row;
    double* z = p.z + row;
    const float* w = p.w + row;
    alpha += row, lx += row, ly += row, lz += row;
    const int* column_phase = t.phase3;
    double* ax = t.ax;
    double* ay = t.ay;
    double* az = t.az;
    double* mx = t.mx + 1;
    double* my = t.my + 1;
    double* mz = t.mz + 1;
    double* bx = t.bx + 2;
    double* by = t.by + 2;
    double* bz = t.bz + 2;
    double violation2 = 0.0;
    const int n = cols - 2;
#pragma omp simd reduction(+ : violation2)
    for (int c = 0; c < n; ++c) {
        const double cx = (x[c] - x[c + 1]) + (x[c + 2] - x[c + 1]);
        const double cy = (y[c] - y[c + 1]) + (y[c + 2] - y[c + 1]);
        const double cz = (z[c] - z[c + 1]) + (z[c + 2] - z[c + 1]);
        const double wa = w[c], wm = w[c + 1], wb = w[c + 2];
        const bool mine = column_phase[c] == phase;
        const double s = mine ? -1.0 / (((wa + 4.0 * wm) + wb) + alpha[c]) : 0.0;
        // Counted where the bend is projected: s is 0 for another phase's bend and -0 for one without stiffness
        // (alpha infinite). With a mask of `mine & (alpha < kInfinite)` here, GCC 12's AVX2 and AVX-512 builds of
        // this loop summed wrong values (the positions were right); tested against the list order.
        violation2 += s != 0.0 ? (cx * cx + cy * cy) + cz * cz : 0.0;
        const double lax = cx * s, lay = cy * s, laz = cz * s;
        lx[c] = mine ? lax : lx[c];
        ly[c] = mine ? lay : ly[c];
        lz[c] = mine ? laz : lz[c];
        const double wm2 = -2.0 * wm;
        ax[c] = wa * lax, ay[c] = wa * lay, az[c] = wa * laz;
        mx[c] = wm2 * lax, my[c] = wm2 * lay, mz[c] = wm2 * laz;
        bx[c] = wb * lax, by[c] = wb * lay, bz[c] = wb * laz;
    }
    for (int c = std::max(n, 0); c < cols; ++c) t.ax[c] = t.ay[c] = t.az[c] = 0.0;  // no bend starts there,
    for (int c : {0, cols - 1}) t.mx[c] = t.my[c] = t.mz[c] = 0.0;     // has its middle there
    for (int c = 0; c < std::min(2, cols); ++c) t.bx[c] = t.by[c] = t.bz[c] = 0.0;     // or ends there
#pragma omp simd
    for (int c = 0; c < cols; ++c) {
        x[c] += (t.ax[c] + t.mx[c]) + t.bx[c];
        y[c] += (t.ay[c] + t.my[c]) + t.by[c];
        z[c] += (t.az[c] + t.mz[c]) + t.bz[c];
    }
    return violation2;
}

// What one projection pass needs; `row` is the calling thread's scratch.
struct Pass {
    Particles p;
    int rows, cols;
    const std::array<std::vector<float>, 6>* rest;
    const std::array<std::vector<double>, 6>* alpha;
    std::array<std::vector<double>, 6>* lambda;
    std::array<DVec3Array, 2>* bend_lambda;
    RowCorrections row;
};

// The stages of a pass, in order (the header's): the elements of one direction. Along a row (Along*) each
// row's elements touch that row only; down (Down*) a row's elements touch it and the `span` rows below.
enum class Stage { AlongSprings, Down, DownRight, DownLeft, AlongSkipOne, DownSkipOne, AlongBends, DownBends };

// Stage `stage`'s batches of rows [first_row, last_row) in row order; returns the sum of C^2.
[[gnu::always_inline]] inline double project_rows(const Pass& pass, Stage stage, int first_row, int last_row) {
    const int cols = pass.cols;
    double violation2 = 0.0;
    // Both lambdas are forced inline: a lambda left out of line is compiled for the baseline instruction set,
    // not for the kernel's (project_avx2 and project_avx512 below).
    auto down = [&](int d, int first_col, int last_col) __attribute__((always_inline)) {
        for (int r = first_row; r < last_row; ++r) {
            violation2 += project_springs(pass.p, (*pass.rest)[d].data(), (*pass.alpha)[d].data(),
                                          (*pass.lambda)[d].data(), r * cols + first_col, r * cols + last_col,
                                          kDirections[d].dr * cols + kDirections[d].dc);
        }
    };
    // Springs along the rows, two apart when Span is 2: every (Span + 1)th column per pass.
    auto along = [&]<int Span>(int d) __attribute__((always_inline)) {
        for (int r = first_row; r < last_row; ++r) {
            for (int phase = 0; phase <= Span; ++phase) {
                violation2 += project_row_springs<Span>(pass.p, (*pass.rest)[d].data(), (*pass.alpha)[d].data(),
                                                        (*pass.lambda)[d].data(), r * cols, cols, phase, pass.row);
            }
        }
    };
    switch (stage) {
        case Stage::AlongSprings: along.template operator()<1>(0); break;
        case Stage::Down: down(1, 0, cols); break;
        case Stage::DownRight: down(2, 0, cols - 1); break;
        case Stage::DownLeft: down(3, 1, cols); break;
        case Stage::AlongSkipOne: along.template operator()<2>(4); break;
        case Stage::DownSkipOne: down(5, 0, cols); break;
        case Stage::AlongBends: {
            DVec3Array& l = (*pass.bend_lambda)[0];
            for (int r = first_row; r < last_row; ++r) {
                for (int phase = 0; phase < 3; ++phase) {
                    violation2 += project_row_bends(pass.p, (*pass.alpha)[4].data(), l.x.data(), l.y.data(),
                                                    l.z.data(), r * cols, cols, phase, pass.row);
                }
            }
        } break;
        case Stage::DownBends: {
            DVec3Array& l = (*pass.bend_lambda)[1];
            for (int r = first_row; r < last_row; ++r) {
                violation2 += project_bends(pass.p, (*pass.alpha)[5].data(), l.x.data(), l.y.data(), l.z.data(),
                                            r * cols, r * cols + cols, cols);
            }
        } break;
    }
    return violation2;
}

// The kernels: the stage compiled for each instruction set, chosen as the fast solver chooses its own. The
// core compiles without contraction into fused multiply-adds, so all three round alike.
double project_generic(const Pass& pass, Stage stage, int first, int last) {
    return project_rows(pass, stage, first, last);
}
__attribute__((target("avx2,fma"))) double project_avx2(const Pass& pass, Stage stage, int first, int last) {
    return project_rows(pass, stage, first, last);
}
__attribute__((target("avx512f,avx512vl,avx2,fma"))) double project_avx512(const Pass& pass, Stage stage, int first,
                                                                           int last) {
    return project_rows(pass, stage, first, last);
}
using Kernel = double (*)(const Pass&, Stage, int, int);

// The substep's start and end, particle by particle: the prediction x += motion + a h^2 with the external
// accelerations a = F w + g - c v, v = motion / h (step_xpbd's accelerations()), keeping the start; and the
// motion x - start (0 for a pinned particle). Branch-free, so each loop vectorises; compiled for each
// instruction set like the projections.
struct Ends {
    double *x, *y, *z, *mx, *my, *mz, *sx, *sy, *sz;
    const float *wind_x, *wind_y, *wind_z, *w;
    const std::uint8_t* pinned;
    glm::dvec3 g;
    double damping, inv_h, h2;
};
[[gnu::always_inline]] inline void predict_range(const Ends& e, std::size_t begin, std::size_t end) {
    double* __restrict x = e.x;
    double* __restrict y = e.y;
    double* __restrict z = e.z;
    double* __restrict sx = e.sx;
    double* __restrict sy = e.sy;
    double* __restrict sz = e.sz;
    for (std::size_t i = begin; i < end; ++i) {
        sx[i] = x[i], sy[i] = y[i], sz[i] = z[i];
        const double wi = e.w[i];
        const double ax = (static_cast<double>(e.wind_x[i]) * wi + e.g.x) - e.damping * (e.mx[i] * e.inv_h);
        const double ay = (static_cast<double>(e.wind_y[i]) * wi + e.g.y) - e.damping * (e.my[i] * e.inv_h);
        const double az = (static_cast<double>(e.wind_z[i]) * wi + e.g.z) - e.damping * (e.mz[i] * e.inv_h);
        const bool held = e.pinned[i] != 0;
        x[i] = held ? x[i] : x[i] + (e.mx[i] + ax * e.h2);
        y[i] = held ? y[i] : y[i] + (e.my[i] + ay * e.h2);
        z[i] = held ? z[i] : z[i] + (e.mz[i] + az * e.h2);
    }
}
[[gnu::always_inline]] inline void motion_range(const Ends& e, std::size_t begin, std::size_t end) {
    double* __restrict mx = e.mx;
    double* __restrict my = e.my;
    double* __restrict mz = e.mz;
    for (std::size_t i = begin; i < end; ++i) {
        const bool held = e.pinned[i] != 0;
        mx[i] = held ? 0.0 : e.x[i] - e.sx[i];
        my[i] = held ? 0.0 : e.y[i] - e.sy[i];
        mz[i] = held ? 0.0 : e.z[i] - e.sz[i];
    }
}
void ends_generic(const Ends& e, bool predict, std::size_t begin, std::size_t end) {
    predict ? predict_range(e, begin, end) : motion_range(e, begin, end);
}
__attribute__((target("avx2,fma"))) void ends_avx2(const Ends& e, bool predict, std::size_t begin, std::size_t end) {
    predict ? predict_range(e, begin, end) : motion_range(e, begin, end);
}
__attribute__((target("avx512f,avx512vl,avx2,fma"))) void ends_avx512(const Ends& e, bool predict, std::size_t begin,
                                                                      std::size_t end) {
    predict ? predict_range(e, begin, end) : motion_range(e, begin, end);
}
using EndsKernel = void (*)(const Ends&, bool, std::size_t, std::size_t);

}  // namespace

std::optional<GridXpbd> GridXpbd::for_topology(const Topology& topology) {
    const int rows = topology.rows, cols = topology.cols;
    if (rows <= 0 || cols <= 0) return std::nullopt;
    const std::size_t n = static_cast<std::size_t>(rows) * cols;
    GridXpbd grid(rows, cols);
    grid.bends_ = !topology.bends.empty();
    for (auto& s : grid.source_) s.assign(n, -1);
    // The direction and start particle of the element from a to b; -1 when it is none of the six.
    auto place = [&](std::uint32_t a, std::uint32_t b, int first_direction, int last_direction) -> std::pair<int, std::uint32_t> {
        if (a >= n || b >= n) return {-1, 0};
        const int dr = static_cast<int>(b / cols) - static_cast<int>(a / cols);
        const int dc = static_cast<int>(b % cols) - static_cast<int>(a % cols);
        for (int d = first_direction; d <= last_direction; ++d) {
            if (dr == kDirections[d].dr && dc == kDirections[d].dc) return {d, a};
            if (dr == -kDirections[d].dr && dc == -kDirections[d].dc) return {d, b};
        }
        return {-1, 0};
    };
    for (std::size_t j = 0; j < topology.springs.size(); ++j) {
        const Spring& s = topology.springs[j];
        const auto [d, start] = s.kind == SpringKind::Structural ? place(s.a, s.b, 0, 1)
                                : s.kind == SpringKind::Shear    ? place(s.a, s.b, 2, 3)
                                                                 : place(s.a, s.b, 4, 5);
        if (d < 0 || (d >= 4 && grid.bends_) || grid.source_[d][start] >= 0) return std::nullopt;
        grid.source_[d][start] = static_cast<int>(j);
    }
    for (std::size_t j = 0; j < topology.bends.size(); ++j) {
        const Bend& b = topology.bends[j];
        const auto [d, start] = place(b.a, b.m, 0, 1);
        const auto [d2, start2] = place(b.m, b.b, 0, 1);
        if (d < 0 || d2 != d || (start == b.a) != (start2 == b.m)) return std::nullopt;  // not three in a line
        const std::uint32_t first = start == b.a ? b.a : b.b;
        if (grid.source_[4 + d][first] >= 0) return std::nullopt;
        grid.source_[4 + d][first] = static_cast<int>(j);
    }
    for (int d = 0; d < 6; ++d) {
        grid.k_[d].assign(n, 0.0f);
        grid.rest_[d].assign(n, 0.0f);
        grid.alpha_[d].assign(n, kInfinite);
        grid.lambda_[d].assign(n, 0.0);
        for (std::size_t i = 0; i < n; ++i) {
            const int j = grid.source_[d][i];
            if (j >= 0 && !(d >= 4 && grid.bends_)) grid.rest_[d][i] = topology.springs[j].rest_length;
        }
    }
    for (DVec3Array& l : grid.bend_lambda_) l.resize(n);
    grid.row_corrections_.assign(9 * static_cast<std::size_t>(cols), 0.0);
    grid.phase2_.resize(cols), grid.phase3_.resize(cols);
    for (int c = 0; c < cols; ++c) grid.phase2_[c] = c % 2, grid.phase3_[c] = c % 3;
    return grid;
}

void GridXpbd::set_stiffness(const Topology& topology, const SpringSettings& springs) {
    for (int d = 0; d < 6; ++d) {
        present_[d] = false;
        for (std::size_t i = 0; i < k_[d].size(); ++i) {
            const int j = source_[d][i];
            float k = 0.0f;
            if (j >= 0) k = d >= 4 && bends_ ? stiffness_of(springs, topology.bends[j]) : stiffness_of(springs, topology.springs[j]);
            k_[d][i] = k;
            present_[d] = present_[d] || k > 0.0f;
        }
    }
    alpha_h_ = 0.0;  // alpha_ follows at the next substep
}

// alpha = 1 / (k w h^2), computed as step_xpbd computes it: 1 / ((k h) h).
void GridXpbd::set_substep(double h) {
    if (h == alpha_h_) return;
    for (int d = 0; d < 6; ++d) {
        for (std::size_t i = 0; i < k_[d].size(); ++i) {
            const double k = k_[d][i];
            alpha_[d][i] = k > 0.0 ? 1.0 / (k * h * h) : kInfinite;
        }
    }
    alpha_h_ = h;
}

int GridXpbd::effective_threads(int requested) const {
    const int bands = (rows_ + kBandRows - 1) / kBandRows;
    const int wanted = requested > 0 ? requested : WorkTeam::cores();
    return std::clamp(std::min(wanted, bands), 1, WorkTeam::kMaxThreads);
}

void GridXpbd::step(State& state, const Dynamics& dynamics, double h, int threads) {
    const std::size_t n = state.size();
    state.substep = h;
    set_substep(h);
    dynamics.external(state, wind_);
    start_.x.resize(n), start_.y.resize(n), start_.z.resize(n);
    const bool automatic = threads == 0;
    int team = effective_threads(threads);
    if (automatic && team > 1 && team_choice_.next_is_single()) team = 1;
    const auto start = std::chrono::steady_clock::now();
    const std::size_t scratch = 9 * static_cast<std::size_t>(cols_);
    if (row_corrections_.size() < team * scratch) row_corrections_.assign(team * scratch, 0.0);
    // The stages this cloth has, in order.
    Stage stages[8];
    int stage_count = 0;
    auto add = [&](bool present, Stage stage) {
        if (present) stages[stage_count++] = stage;
    };
    add(present_[0], Stage::AlongSprings);
    add(present_[1], Stage::Down);
    add(present_[2], Stage::DownRight);
    add(present_[3], Stage::DownLeft);
    add(!bends_ && present_[4], Stage::AlongSkipOne);
    add(!bends_ && present_[5], Stage::DownSkipOne);
    add(bends_ && present_[4], Stage::AlongBends);
    add(bends_ && present_[5], Stage::DownBends);
    Kernel kernel = project_generic;
    EndsKernel ends_kernel = ends_generic;
    if (FastSolver::kernel() == FastKernel::Avx2) kernel = project_avx2, ends_kernel = ends_avx2;
    if (FastSolver::kernel() == FastKernel::Avx512) kernel = project_avx512, ends_kernel = ends_avx512;
    const int rows = rows_, bands = (rows_ + kBandRows - 1) / kBandRows;
    const double h2 = h * h, inv_h = 1.0 / h, damping = dynamics.damping;
    const glm::dvec3 g(dynamics.gravity);
    double* x = state.position.x.data();
    double* y = state.position.y.data();
    double* z = state.position.z.data();
    double* mx = state.motion.x.data();
    double* my = state.motion.y.data();
    double* mz = state.motion.z.data();
    const float* w = state.inverse_mass.data();
    const std::uint8_t* pinned = state.pinned.data();
    // Each worker's pass: its own rows of corrections (work_team.hpp: worker 0 .. team - 1).
    std::vector<Pass> passes(static_cast<std::size_t>(team));
    const std::size_t c = static_cast<std::size_t>(cols_);
    for (int k = 0; k < team; ++k) {
        double* r = row_corrections_.data() + static_cast<std::size_t>(k) * scratch;
        passes[static_cast<std::size_t>(k)] = Pass{{x, y, z, w}, rows_, cols_, &rest_, &alpha_, &lambda_, &bend_lambda_,
                                                   {r, r + c, r + 2 * c, r + 3 * c, r + 4 * c, r + 5 * c, r + 6 * c,
                                                    r + 7 * c, r + 8 * c, phase2_.data(), phase3_.data()}};
    }
    WorkTeam& work_team = WorkTeam::shared();
    // Particles in chunks of kParticleChunk, rows in chunks of kRowChunk: pieces small enough that a
    // descheduled thread holds up little (work_team.hpp).
    constexpr std::size_t kParticleChunk = 4096;
    constexpr int kRowChunk = 4;
    const int particle_chunks = static_cast<int>((n + kParticleChunk - 1) / kParticleChunk);
    const int row_chunks = (rows + kRowChunk - 1) / kRowChunk;
    // Each piece's sum of C^2 in its own slot, summed in index order: the same for any team.
    std::vector<double> violation(static_cast<std::size_t>(std::max(row_chunks, bands)), 0.0);
    double violation2 = 0.0;
    auto sum_violation = [&](int pieces) {
        for (int k = 0; k < pieces; ++k) violation2 += violation[static_cast<std::size_t>(k)];
    };
    const Ends ends{x, y, z, mx, my, mz, start_.x.data(), start_.y.data(), start_.z.data(), wind_.x.data(), wind_.y.data(),
                    wind_.z.data(), w, pinned, g, damping, inv_h, h2};
    auto each_chunk = [&](bool predict) {
        work_team.run(team, particle_chunks, [&](int chunk, int) {
            const std::size_t begin = static_cast<std::size_t>(chunk) * kParticleChunk;
            ends_kernel(ends, predict, begin, std::min(n, begin + kParticleChunk));
        });
    };
    each_chunk(true);
    for (int k = 0; k < stage_count; ++k) {
        const Stage stage = stages[k];
        if (stage == Stage::AlongSprings || stage == Stage::AlongSkipOne || stage == Stage::AlongBends) {
            work_team.run(team, row_chunks, [&](int chunk, int worker) {
                const int first = chunk * kRowChunk, last = std::min(rows, first + kRowChunk);
                double v = 0.0;
                for (int row = first; row < last; ++row) v += kernel(passes[static_cast<std::size_t>(worker)], stage, row, row + 1);
                violation[static_cast<std::size_t>(chunk)] = v;
            });
            sum_violation(row_chunks);
            continue;
        }
        // Down: each band of rows from its top, all at once; then the rows whose elements reach into the
        // next band, each band's from its top (the order does not depend on the thread count).
        const int span = stage == Stage::DownSkipOne || stage == Stage::DownBends ? 2 : 1;
        work_team.run(team, bands, [&](int b, int worker) {
            const int first = b * kBandRows, last = std::min(rows, first + kBandRows);
            violation[static_cast<std::size_t>(b)] =
                kernel(passes[static_cast<std::size_t>(worker)], stage, first, last - span);  // none reaches past `last`
        });
        sum_violation(bands);
        work_team.run(team, bands, [&](int b, int worker) {
            const int first = b * kBandRows, last = std::min(rows, first + kBandRows);
            violation[static_cast<std::size_t>(b)] = kernel(passes[static_cast<std::size_t>(worker)], stage,
                                                            std::max(first, last - span), std::min(last, rows - span));
        });
        sum_violation(bands);
    }
    each_chunk(false);
    if (automatic && effective_threads(0) > 1) team_choice_.record(team == 1, std::chrono::steady_clock::now() - start);
    last_threads_ = team;
    substep_ = h;
    initial_violation_ = std::sqrt(violation2);
}

double GridXpbd::residual(const DVec3Array& position) const {
    if (substep_ == 0.0) return 0.0;
    const double h2 = substep_ * substep_;
    double residual2 = 0.0;
    const std::size_t n = position.size();
    for (int d = 0; d < 6; ++d) {
        if (!present_[d]) continue;
        const int offset = kDirections[d].dr * cols_ + kDirections[d].dc;
        const bool bend = d >= 4 && bends_;
        for (std::size_t i = 0; i < n; ++i) {
            if (!(k_[d][i] > 0.0f)) continue;
            const double k = k_[d][i];
            if (bend) {
                const DVec3Array& l = bend_lambda_[d - 4];
                const std::size_t m = i + offset / 2, b = i + offset;
                const glm::dvec3 pm = position.get(m);
                const glm::dvec3 c = (position.get(i) - pm) + (position.get(b) - pm);
                const glm::dvec3 r = c + l.get(i) / (k * h2);
                residual2 += glm::dot(r, r);
            } else {
                const double c = glm::length(position.get(i + offset) - position.get(i)) - rest_[d][i];
                const double r = c + lambda_[d][i] / (k * h2);
                residual2 += r * r;
            }
        }
    }
    return initial_violation_ > 0.0 ? std::sqrt(residual2) / initial_violation_ : 0.0;
}

}  // namespace clothsim
