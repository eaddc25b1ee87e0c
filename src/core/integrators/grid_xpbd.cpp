#include "integrators/grid_xpbd.hpp"
#include "integrators/xpbd_projection.hpp"

#include "integrators/fast_solver.hpp"
#include "integrators/work_team.hpp"
#include "model/forces.hpp"

#include <algorithm>
#include <chrono>

#include <cmath>
#include <immintrin.h>
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
// With a stretch curve (Curved), each spring takes its secant compliance as step_xpbd does (xpbd_projection.hpp).
template <bool Curved = false>
[[gnu::always_inline]] inline double project_springs(const Particles& p, const float* rest, const double* alpha,
                                                     double* lambda, int first, int last, int offset,
                                                     const SpringCurve* curve = nullptr) {
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
        const double a = Curved ? curved_compliance(alpha[i], *curve, c, static_cast<double>(rest[i])) : alpha[i];
        const double l = -c / ((wa + wb) + a);
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

// The elements along a row (directions 0 and 4) are stored by pass: a row's slots hold first the elements
// starting in the columns that are 0 modulo Span + 1, in column order, then those that are 1 modulo Span + 1,
// and so on (GridXpbd::slot). A pass then reads its rest lengths, compliances and multipliers contiguously,
// and its particles (Span + 1) apart (strided loops here; the AVX2 kernels below transpose them in registers).

// The elements of a pass along a row of `cols`: those starting in the columns c = phase + (span + 1) k that end
// in the row, c + span < cols.
constexpr int along_count(int cols, int span, int phase) { return std::max(0, (cols - phase) / (span + 1)); }

// The springs along row `row` from column c to c + Span whose column is `phase` modulo Span + 1: no two share a
// particle. `first_slot` is the pass's first slot in the row; arithmetic as project_springs.
template <int Span, bool Curved = false>
[[gnu::always_inline]] inline double project_row_springs(const Particles& p, const float* rest, const double* alpha,
                                                         double* lambda, int row, int cols, int phase, int first_slot,
                                                         int first = 0, const SpringCurve* curve = nullptr) {
    double* x = p.x + row + phase;
    double* y = p.y + row + phase;
    double* z = p.z + row + phase;
    const float* w = p.w + row + phase;
    rest += row + first_slot, alpha += row + first_slot, lambda += row + first_slot;
    double violation2 = 0.0;
    const int count = along_count(cols, Span, phase);
#pragma omp simd reduction(+ : violation2)
    for (int k = first; k < count; ++k) {
        const int a = (Span + 1) * k, b = a + Span;
        const double dx = x[b] - x[a], dy = y[b] - y[a], dz = z[b] - z[a];
        const double length = std::sqrt((dx * dx + dy * dy) + dz * dz);
        const double e = length - static_cast<double>(rest[k]);
        const double wa = w[a], wb = w[b];
        const double ak = Curved ? curved_compliance(alpha[k], *curve, e, static_cast<double>(rest[k])) : alpha[k];
        const double l = -e / ((wa + wb) + ak);
        const bool ok = (length > 1e-12) & (alpha[k] < kInfinite);
        const double g = ok ? l / length : 0.0;
        lambda[k] = ok ? l : 0.0;
        violation2 += ok ? e * e : 0.0;
        const double ga = -(wa * g), gb = wb * g;
        x[a] += dx * ga;
        y[a] += dy * ga;
        z[a] += dz * ga;
        x[b] += dx * gb;
        y[b] += dy * gb;
        z[b] += dz * gb;
    }
    return violation2;
}

// The bends along row `row` (columns c, c + 1, c + 2) whose first column is `phase` modulo 3, as
// project_row_springs; arithmetic as project_bends.
[[gnu::always_inline]] inline double project_row_bends(const Particles& p, const double* alpha, double* lx, double* ly,
                                                       double* lz, int row, int cols, int phase, int first_slot,
                                                       int first = 0) {
    double* x = p.x + row + phase;
    double* y = p.y + row + phase;
    double* z = p.z + row + phase;
    const float* w = p.w + row + phase;
    const int at = row + first_slot;
    alpha += at, lx += at, ly += at, lz += at;
    double violation2 = 0.0;
    const int count = along_count(cols, 2, phase);
#pragma omp simd reduction(+ : violation2)
    for (int k = first; k < count; ++k) {
        const int a = 3 * k, m = a + 1, b = a + 2;
        const double cx = (x[a] - x[m]) + (x[b] - x[m]);
        const double cy = (y[a] - y[m]) + (y[b] - y[m]);
        const double cz = (z[a] - z[m]) + (z[b] - z[m]);
        const double wa = w[a], wm = w[m], wb = w[b];
        const double s = -1.0 / (((wa + 4.0 * wm) + wb) + alpha[k]);
        const bool ok = alpha[k] < kInfinite;
        violation2 += ok ? (cx * cx + cy * cy) + cz * cz : 0.0;
        const double ax = cx * s, ay = cy * s, az = cz * s;
        lx[k] = ax, ly[k] = ay, lz[k] = az;
        const double wm2 = -2.0 * wm;
        x[a] += wa * ax, y[a] += wa * ay, z[a] += wa * az;
        x[m] += wm2 * ax, y[m] += wm2 * ay, z[m] += wm2 * az;
        x[b] += wb * ax, y[b] += wb * ay, z[b] += wb * az;
    }
    return violation2;
}

// What one projection pass needs.
struct Pass {
    Particles p;
    int rows, cols;
    const std::array<std::vector<float>, 6>* rest;
    const std::array<std::vector<double>, 6>* alpha;
    std::array<std::vector<double>, 6>* lambda;
    std::array<DVec3Array, 2>* bend_lambda;
    const std::array<std::array<int, 3>, 2>* first_slot;  // GridXpbd::first_slot_
    const std::array<SpringCurve, 2>* curve;              // the structural springs' along u (d = 0), along v (d = 1)
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
        const SpringCurve* curve = d == 1 && (*pass.curve)[1].knots ? &(*pass.curve)[1] : nullptr;
        for (int r = first_row; r < last_row; ++r) {
            if (curve) {
                violation2 += project_springs<true>(pass.p, (*pass.rest)[d].data(), (*pass.alpha)[d].data(),
                                                    (*pass.lambda)[d].data(), r * cols + first_col, r * cols + last_col,
                                                    kDirections[d].dr * cols + kDirections[d].dc, curve);
            } else {
                violation2 += project_springs(pass.p, (*pass.rest)[d].data(), (*pass.alpha)[d].data(),
                                              (*pass.lambda)[d].data(), r * cols + first_col, r * cols + last_col,
                                              kDirections[d].dr * cols + kDirections[d].dc);
            }
        }
    };
    // Springs along the rows, two apart when Span is 2: every (Span + 1)th column per pass.
    auto along = [&]<int Span>(int d) __attribute__((always_inline)) {
        for (int r = first_row; r < last_row; ++r) {
            for (int phase = 0; phase <= Span; ++phase) {
                if (d == 0 && (*pass.curve)[0].knots) {
                    violation2 += project_row_springs<Span, true>(pass.p, (*pass.rest)[d].data(), (*pass.alpha)[d].data(),
                                                                  (*pass.lambda)[d].data(), r * cols, cols, phase,
                                                                  (*pass.first_slot)[Span - 1][phase], 0, &(*pass.curve)[0]);
                } else {
                    violation2 += project_row_springs<Span>(pass.p, (*pass.rest)[d].data(), (*pass.alpha)[d].data(),
                                                            (*pass.lambda)[d].data(), r * cols, cols, phase,
                                                            (*pass.first_slot)[Span - 1][phase]);
                }
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
                                                    l.z.data(), r * cols, cols, phase, (*pass.first_slot)[1][phase]);
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

// The passes along the rows with AVX2, four elements at a time. A pass's particles lie (span + 1) apart; they
// are loaded as contiguous vectors and transposed in registers with two 128-bit lane swaps and in-lane
// shuffles per coordinate (the compiler's strided loop spent a lane-crossing permute per element and ran at
// half the speed of the passes down). Arithmetic as project_row_springs and project_row_bends, which take the
// last count % 4 elements.

// Particles v[0 .. 7] as the ends of four springs: a = v[0], v[2], v[4], v[6]; b = v[1], v[3], v[5], v[7].
__attribute__((target("avx2,fma"))) inline void split_pairs(__m256d v0, __m256d v1, __m256d& a, __m256d& b) {
    const __m256d p0 = _mm256_permute2f128_pd(v0, v1, 0x20);  // v0 v1 | v4 v5
    const __m256d p1 = _mm256_permute2f128_pd(v0, v1, 0x31);  // v2 v3 | v6 v7
    a = _mm256_unpacklo_pd(p0, p1);
    b = _mm256_unpackhi_pd(p0, p1);
}
__attribute__((target("avx2,fma"))) inline void store_pairs(double* v, __m256d a, __m256d b) {
    const __m256d p0 = _mm256_unpacklo_pd(a, b), p1 = _mm256_unpackhi_pd(a, b);
    _mm256_storeu_pd(v, _mm256_permute2f128_pd(p0, p1, 0x20));
    _mm256_storeu_pd(v + 4, _mm256_permute2f128_pd(p0, p1, 0x31));
}
// Particles v[0 .. 11] as the three particles of four bends: a = v[0], v[3], v[6], v[9]; m = v[1], ...; b = v[2], ...
__attribute__((target("avx2,fma"))) inline void split_triples(__m256d v0, __m256d v1, __m256d v2, __m256d& a,
                                                              __m256d& m, __m256d& b) {
    const __m256d p0 = _mm256_permute2f128_pd(v0, v1, 0x30);  // v0 v1 | v6 v7
    const __m256d p1 = _mm256_permute2f128_pd(v0, v2, 0x21);  // v2 v3 | v8 v9
    const __m256d p2 = _mm256_permute2f128_pd(v1, v2, 0x30);  // v4 v5 | v10 v11
    a = _mm256_shuffle_pd(p0, p1, 0b1010);
    m = _mm256_shuffle_pd(p0, p2, 0b0101);
    b = _mm256_shuffle_pd(p1, p2, 0b1010);
}
__attribute__((target("avx2,fma"))) inline void store_triples(double* v, __m256d a, __m256d m, __m256d b) {
    const __m256d p0 = _mm256_unpacklo_pd(a, m);        // v0 v1 | v6 v7
    const __m256d p1 = _mm256_shuffle_pd(b, a, 0b1010);  // v2 v3 | v8 v9
    const __m256d p2 = _mm256_unpackhi_pd(m, b);        // v4 v5 | v10 v11
    _mm256_storeu_pd(v, _mm256_permute2f128_pd(p0, p1, 0x20));
    _mm256_storeu_pd(v + 4, _mm256_permute2f128_pd(p2, p0, 0x30));
    _mm256_storeu_pd(v + 8, _mm256_permute2f128_pd(p1, p2, 0x31));
}
__attribute__((target("avx2,fma"))) inline double horizontal_sum(__m256d v) {
    const __m128d s = _mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
    return _mm_cvtsd_f64(_mm_add_sd(s, _mm_unpackhi_pd(s, s)));
}

__attribute__((target("avx2,fma"))) double along_springs_avx2(const Pass& pass, int first_row, int last_row) {
    const int cols = pass.cols;
    const float* rest_all = (*pass.rest)[0].data();
    const double* alpha_all = (*pass.alpha)[0].data();
    double* lambda_all = (*pass.lambda)[0].data();
    const __m256d sign = _mm256_set1_pd(-0.0), tiny = _mm256_set1_pd(1e-12), infinite = _mm256_set1_pd(kInfinite);
    double violation2 = 0.0;
    for (int r = first_row; r < last_row; ++r) {
        for (int phase = 0; phase < 2; ++phase) {
            const int row = r * cols, first_slot = (*pass.first_slot)[0][phase];
            double* x = pass.p.x + row + phase;
            double* y = pass.p.y + row + phase;
            double* z = pass.p.z + row + phase;
            const float* w = pass.p.w + row + phase;
            const float* rest = rest_all + row + first_slot;
            const double* alpha = alpha_all + row + first_slot;
            double* lambda = lambda_all + row + first_slot;
            const int count = along_count(cols, 1, phase);
            __m256d sum = _mm256_setzero_pd();
            int k = 0;
            for (; k + 4 <= count; k += 4) {
                const int i = 2 * k;
                __m256d xa, xb, ya, yb, za, zb, wa, wb;
                split_pairs(_mm256_loadu_pd(x + i), _mm256_loadu_pd(x + i + 4), xa, xb);
                split_pairs(_mm256_loadu_pd(y + i), _mm256_loadu_pd(y + i + 4), ya, yb);
                split_pairs(_mm256_loadu_pd(z + i), _mm256_loadu_pd(z + i + 4), za, zb);
                split_pairs(_mm256_cvtps_pd(_mm_loadu_ps(w + i)), _mm256_cvtps_pd(_mm_loadu_ps(w + i + 4)), wa, wb);
                const __m256d dx = _mm256_sub_pd(xb, xa), dy = _mm256_sub_pd(yb, ya), dz = _mm256_sub_pd(zb, za);
                const __m256d length = _mm256_sqrt_pd(
                    _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz)));
                const __m256d e = _mm256_sub_pd(length, _mm256_cvtps_pd(_mm_loadu_ps(rest + k)));
                const __m256d a = _mm256_loadu_pd(alpha + k);
                const __m256d l = _mm256_div_pd(_mm256_xor_pd(e, sign), _mm256_add_pd(_mm256_add_pd(wa, wb), a));
                const __m256d ok = _mm256_and_pd(_mm256_cmp_pd(length, tiny, _CMP_GT_OQ), _mm256_cmp_pd(a, infinite, _CMP_LT_OQ));
                const __m256d g = _mm256_and_pd(ok, _mm256_div_pd(l, length));
                _mm256_storeu_pd(lambda + k, _mm256_and_pd(ok, l));
                sum = _mm256_add_pd(sum, _mm256_and_pd(ok, _mm256_mul_pd(e, e)));
                const __m256d ga = _mm256_xor_pd(_mm256_mul_pd(wa, g), sign), gb = _mm256_mul_pd(wb, g);
                store_pairs(x + i, _mm256_add_pd(xa, _mm256_mul_pd(dx, ga)), _mm256_add_pd(xb, _mm256_mul_pd(dx, gb)));
                store_pairs(y + i, _mm256_add_pd(ya, _mm256_mul_pd(dy, ga)), _mm256_add_pd(yb, _mm256_mul_pd(dy, gb)));
                store_pairs(z + i, _mm256_add_pd(za, _mm256_mul_pd(dz, ga)), _mm256_add_pd(zb, _mm256_mul_pd(dz, gb)));
            }
            violation2 += horizontal_sum(sum);
            violation2 += project_row_springs<1>(pass.p, rest_all, alpha_all, lambda_all, row, cols, phase, first_slot, k);
        }
    }
    return violation2;
}

__attribute__((target("avx2,fma"))) double along_bends_avx2(const Pass& pass, int first_row, int last_row) {
    const int cols = pass.cols;
    const double* alpha_all = (*pass.alpha)[4].data();
    DVec3Array& l = (*pass.bend_lambda)[0];
    const __m256d infinite = _mm256_set1_pd(kInfinite), minus_one = _mm256_set1_pd(-1.0),
                  four = _mm256_set1_pd(4.0), minus_two = _mm256_set1_pd(-2.0);
    double violation2 = 0.0;
    for (int r = first_row; r < last_row; ++r) {
        for (int phase = 0; phase < 3; ++phase) {
            const int row = r * cols, first_slot = (*pass.first_slot)[1][phase];
            double* x = pass.p.x + row + phase;
            double* y = pass.p.y + row + phase;
            double* z = pass.p.z + row + phase;
            const float* w = pass.p.w + row + phase;
            const double* alpha = alpha_all + row + first_slot;
            double* lx = l.x.data() + row + first_slot;
            double* ly = l.y.data() + row + first_slot;
            double* lz = l.z.data() + row + first_slot;
            const int count = along_count(cols, 2, phase);
            __m256d sum = _mm256_setzero_pd();
            int k = 0;
            for (; k + 4 <= count; k += 4) {
                const int i = 3 * k;
                __m256d xa, xm, xb, ya, ym, yb, za, zm, zb, wa, wm, wb;
                split_triples(_mm256_loadu_pd(x + i), _mm256_loadu_pd(x + i + 4), _mm256_loadu_pd(x + i + 8), xa, xm, xb);
                split_triples(_mm256_loadu_pd(y + i), _mm256_loadu_pd(y + i + 4), _mm256_loadu_pd(y + i + 8), ya, ym, yb);
                split_triples(_mm256_loadu_pd(z + i), _mm256_loadu_pd(z + i + 4), _mm256_loadu_pd(z + i + 8), za, zm, zb);
                split_triples(_mm256_cvtps_pd(_mm_loadu_ps(w + i)), _mm256_cvtps_pd(_mm_loadu_ps(w + i + 4)),
                              _mm256_cvtps_pd(_mm_loadu_ps(w + i + 8)), wa, wm, wb);
                const __m256d cx = _mm256_add_pd(_mm256_sub_pd(xa, xm), _mm256_sub_pd(xb, xm));
                const __m256d cy = _mm256_add_pd(_mm256_sub_pd(ya, ym), _mm256_sub_pd(yb, ym));
                const __m256d cz = _mm256_add_pd(_mm256_sub_pd(za, zm), _mm256_sub_pd(zb, zm));
                const __m256d a = _mm256_loadu_pd(alpha + k);
                const __m256d s = _mm256_div_pd(
                    minus_one, _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(wa, _mm256_mul_pd(four, wm)), wb), a));
                const __m256d ok = _mm256_cmp_pd(a, infinite, _CMP_LT_OQ);
                sum = _mm256_add_pd(sum, _mm256_and_pd(ok, _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(cx, cx), _mm256_mul_pd(cy, cy)),
                                                                          _mm256_mul_pd(cz, cz))));
                const __m256d ax = _mm256_mul_pd(cx, s), ay = _mm256_mul_pd(cy, s), az = _mm256_mul_pd(cz, s);
                _mm256_storeu_pd(lx + k, ax);
                _mm256_storeu_pd(ly + k, ay);
                _mm256_storeu_pd(lz + k, az);
                const __m256d wm2 = _mm256_mul_pd(minus_two, wm);
                store_triples(x + i, _mm256_add_pd(xa, _mm256_mul_pd(wa, ax)), _mm256_add_pd(xm, _mm256_mul_pd(wm2, ax)),
                              _mm256_add_pd(xb, _mm256_mul_pd(wb, ax)));
                store_triples(y + i, _mm256_add_pd(ya, _mm256_mul_pd(wa, ay)), _mm256_add_pd(ym, _mm256_mul_pd(wm2, ay)),
                              _mm256_add_pd(yb, _mm256_mul_pd(wb, ay)));
                store_triples(z + i, _mm256_add_pd(za, _mm256_mul_pd(wa, az)), _mm256_add_pd(zm, _mm256_mul_pd(wm2, az)),
                              _mm256_add_pd(zb, _mm256_mul_pd(wb, az)));
            }
            violation2 += horizontal_sum(sum);
            violation2 += project_row_bends(pass.p, alpha_all, l.x.data(), l.y.data(), l.z.data(), row, cols, phase,
                                            first_slot, k);
        }
    }
    return violation2;
}

// The kernels: the stage compiled for each instruction set, chosen as the fast solver chooses its own. The
// core compiles without contraction into fused multiply-adds, so all three round alike.
double project_generic(const Pass& pass, Stage stage, int first, int last) {
    return project_rows(pass, stage, first, last);
}
// A curved material's springs along the rows take the scalar order (project_rows), the same arithmetic.
__attribute__((target("avx2,fma"))) double project_avx2(const Pass& pass, Stage stage, int first, int last) {
    if (stage == Stage::AlongSprings && !(*pass.curve)[0].knots) return along_springs_avx2(pass, first, last);
    if (stage == Stage::AlongBends) return along_bends_avx2(pass, first, last);
    return project_rows(pass, stage, first, last);
}
// The passes along the rows as AVX2's (four lanes are enough for their shuffles).
__attribute__((target("avx512f,avx512vl,avx2,fma"))) double project_avx512(const Pass& pass, Stage stage, int first,
                                                                           int last) {
    if (stage == Stage::AlongSprings && !(*pass.curve)[0].knots) return along_springs_avx2(pass, first, last);
    if (stage == Stage::AlongBends) return along_bends_avx2(pass, first, last);
    return project_rows(pass, stage, first, last);
}
using Kernel = double (*)(const Pass&, Stage, int, int);

// The substep's start and end, particle by particle: the prediction x += motion + a h^2 with the external
// accelerations a = F w + g - c v, v = motion / h (step_xpbd's accelerations()), keeping the start; and the
// motion x - start (0 for a pinned particle). Selects instead of branches, so each loop vectorises; compiled for each
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
    const double* __restrict mx = e.mx;
    const double* __restrict my = e.my;
    const double* __restrict mz = e.mz;
    const float* __restrict fx = e.wind_x;
    const float* __restrict fy = e.wind_y;
    const float* __restrict fz = e.wind_z;
    const float* __restrict w = e.w;
    const std::uint8_t* __restrict pinned = e.pinned;
    const double gx = e.g.x, gy = e.g.y, gz = e.g.z, damping = e.damping, inv_h = e.inv_h, h2 = e.h2;
#pragma omp simd
    for (std::size_t i = begin; i < end; ++i) {
        const double x0 = x[i], y0 = y[i], z0 = z[i];
        sx[i] = x0, sy[i] = y0, sz[i] = z0;
        const double wi = w[i];
        const double ax = (static_cast<double>(fx[i]) * wi + gx) - damping * (mx[i] * inv_h);
        const double ay = (static_cast<double>(fy[i]) * wi + gy) - damping * (my[i] * inv_h);
        const double az = (static_cast<double>(fz[i]) * wi + gz) - damping * (mz[i] * inv_h);
        const double nx = x0 + (mx[i] + ax * h2), ny = y0 + (my[i] + ay * h2), nz = z0 + (mz[i] + az * h2);
        const bool held = pinned[i] != 0;
        x[i] = held ? x0 : nx;
        y[i] = held ? y0 : ny;
        z[i] = held ? z0 : nz;
    }
}
[[gnu::always_inline]] inline void motion_range(const Ends& e, std::size_t begin, std::size_t end) {
    double* __restrict mx = e.mx;
    double* __restrict my = e.my;
    double* __restrict mz = e.mz;
    const double* __restrict x = e.x;
    const double* __restrict y = e.y;
    const double* __restrict z = e.z;
    const double* __restrict sx = e.sx;
    const double* __restrict sy = e.sy;
    const double* __restrict sz = e.sz;
    const std::uint8_t* __restrict pinned = e.pinned;
#pragma omp simd
    for (std::size_t i = begin; i < end; ++i) {
        const bool held = pinned[i] != 0;
        const double dx = x[i] - sx[i], dy = y[i] - sy[i], dz = z[i] - sz[i];
        mx[i] = held ? 0.0 : dx;
        my[i] = held ? 0.0 : dy;
        mz[i] = held ? 0.0 : dz;
    }
}
[[gnu::always_inline]] inline void ends_range(const Ends& e, bool predict, std::size_t begin, std::size_t end) {
    predict ? predict_range(e, begin, end) : motion_range(e, begin, end);
}
void ends_generic(const Ends& e, bool predict, std::size_t begin, std::size_t end) {
    ends_range(e, predict, begin, end);
}
__attribute__((target("avx2,fma"))) void ends_avx2(const Ends& e, bool predict, std::size_t begin, std::size_t end) {
    ends_range(e, predict, begin, end);
}
__attribute__((target("avx512f,avx512vl,avx2,fma"))) void ends_avx512(const Ends& e, bool predict, std::size_t begin,
                                                                      std::size_t end) {
    ends_range(e, predict, begin, end);
}
using EndsKernel = void (*)(const Ends&, bool, std::size_t, std::size_t);

}  // namespace

std::optional<GridXpbd> GridXpbd::for_topology(const Topology& topology) {
    const int rows = topology.rows, cols = topology.cols;
    if (rows <= 0 || cols <= 0) return std::nullopt;
    const std::size_t n = static_cast<std::size_t>(rows) * cols;
    GridXpbd grid(rows, cols);
    grid.bends_ = !topology.bends.empty();
    for (int span = 1; span <= 2; ++span) {
        int slot = 0;
        for (int phase = 0; phase <= span; ++phase) {
            grid.first_slot_[span - 1][phase] = slot;
            slot += (cols - phase + span) / (span + 1);  // the columns that are `phase` modulo span + 1
        }
    }
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
        if (d < 0 || (d >= 4 && grid.bends_) || grid.source_[d][grid.slot(d, start)] >= 0) return std::nullopt;
        grid.source_[d][grid.slot(d, start)] = static_cast<int>(j);
    }
    for (std::size_t j = 0; j < topology.bends.size(); ++j) {
        const Bend& b = topology.bends[j];
        const auto [d, start] = place(b.a, b.m, 0, 1);
        const auto [d2, start2] = place(b.m, b.b, 0, 1);
        if (d < 0 || d2 != d || (start == b.a) != (start2 == b.m)) return std::nullopt;  // not three in a line
        const std::uint32_t first = start == b.a ? b.a : b.b;
        if (grid.source_[4 + d][grid.slot(4 + d, first)] >= 0) return std::nullopt;
        grid.source_[4 + d][grid.slot(4 + d, first)] = static_cast<int>(j);
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
    return grid;
}

std::size_t GridXpbd::slot(int d, std::size_t start) const {
    if (d != 0 && d != 4) return start;
    const int span = d == 0 ? 1 : 2;
    const std::size_t row = start / static_cast<std::size_t>(cols_) * static_cast<std::size_t>(cols_);
    const int c = static_cast<int>(start - row);
    return row + static_cast<std::size_t>(first_slot_[span - 1][c % (span + 1)] + c / (span + 1));
}

std::size_t GridXpbd::start_of(int d, std::size_t slot) const {
    if (d != 0 && d != 4) return slot;
    const int span = d == 0 ? 1 : 2;
    const std::size_t row = slot / static_cast<std::size_t>(cols_) * static_cast<std::size_t>(cols_);
    const int s = static_cast<int>(slot - row);
    int phase = span;
    while (s < first_slot_[span - 1][phase]) --phase;
    return row + static_cast<std::size_t>(phase + (span + 1) * (s - first_slot_[span - 1][phase]));
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
    curve_ = springs.stretch_curve;
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
    const Pass pass{{x, y, z, w}, rows_, cols_, &rest_, &alpha_, &lambda_, &bend_lambda_, &first_slot_, &curve_};
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
            work_team.run(team, row_chunks, [&](int chunk, int) {
                const int first = chunk * kRowChunk, last = std::min(rows, first + kRowChunk);
                double v = 0.0;
                for (int row = first; row < last; ++row) v += kernel(pass, stage, row, row + 1);
                violation[static_cast<std::size_t>(chunk)] = v;
            });
            sum_violation(row_chunks);
            continue;
        }
        // Down: each band of rows from its top, all at once; then the rows whose elements reach into the
        // next band, each band's from its top (the order does not depend on the thread count).
        const int span = stage == Stage::DownSkipOne || stage == Stage::DownBends ? 2 : 1;
        work_team.run(team, bands, [&](int b, int) {
            const int first = b * kBandRows, last = std::min(rows, first + kBandRows);
            violation[static_cast<std::size_t>(b)] =
                kernel(pass, stage, first, last - span);  // none reaches past `last`
        });
        sum_violation(bands);
        work_team.run(team, bands, [&](int b, int) {
            const int first = b * kBandRows, last = std::min(rows, first + kBandRows);
            violation[static_cast<std::size_t>(b)] = kernel(pass, stage,
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
        static const SpringCurve kLinear{};
        const SpringCurve& curve = d < 2 ? curve_[d] : kLinear;
        for (std::size_t e = 0; e < n; ++e) {
            if (!(k_[d][e] > 0.0f)) continue;
            const double k = k_[d][e];
            const std::size_t i = start_of(d, e);
            if (bend) {
                const DVec3Array& l = bend_lambda_[d - 4];
                const std::size_t m = i + offset / 2, b = i + offset;
                const glm::dvec3 pm = position.get(m);
                const glm::dvec3 c = (position.get(i) - pm) + (position.get(b) - pm);
                const glm::dvec3 r = c + l.get(e) / (k * h2);
                residual2 += glm::dot(r, r);
            } else {
                const double c = glm::length(position.get(i + offset) - position.get(i)) - rest_[d][e];
                const double r = spring_residual(c, lambda_[d][e], k, h2, curve, rest_[d][e]);
                residual2 += r * r;
            }
        }
    }
    return initial_violation_ > 0.0 ? std::sqrt(residual2) / initial_violation_ : 0.0;
}

}  // namespace clothsim
