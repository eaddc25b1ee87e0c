#include "integrators/fast_solver.hpp"
#include "integrators/work_team.hpp"

#include "collision/broad_phase.hpp"
#include "integrators/verlet.hpp"

#include <immintrin.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>
#include <utility>

namespace clothsim {
namespace {

// A stored spring row: a cache line of zero floats each side (so c - 2 and c + 1 are readable) and a stride of
// whole lines, so that in the 64-byte-aligned buffers column 0 of every row starts a line and the row
// update's vector loads at whole-vector columns do not split two lines (docs/PERFORMANCE.md).
constexpr int kPad = 16;
inline std::size_t spring_row_stride(int cols) {
    return (static_cast<std::size_t>(cols) + 2 * kPad + 15) & ~std::size_t{15};
}
// Bit 3 of a sweep's mask: directions 4 and 5 are bends (the spring kinds take bits 0-2, step_plan.hpp).
constexpr unsigned kBendsBit = 8u;

struct Direction {
    int dr, dc;
    SpringKind kind;
};
constexpr std::array<Direction, 6> kDirections = {{
    {0, 1, SpringKind::Structural},
    {1, 0, SpringKind::Structural},
    {1, 1, SpringKind::Shear},
    {1, -1, SpringKind::Shear},
    {0, 2, SpringKind::Bending},
    {2, 0, SpringKind::Bending},
}};

// Columns c whose spring (r, c) -> (r + dr, c + dc) lies inside the grid.
int first_column(const Direction& d) { return std::max(0, -d.dc); }
int end_column(const Direction& d, int cols) { return cols - std::max(0, d.dc); }

// Spring forces of one run of springs, F_a = s d with s = k (|d| - L0) / |d| (s = k for L0 = 0; no force
// when the ends of a spring with L0 > 0 coincide). Positions are double: d is their difference taken in
// double and rounded once to float (relative error 6e-8 of d itself, where rounding the positions first
// would leave an absolute 6e-8 m of the position: 25x the error on the accuracy study's drape), then float
// arithmetic. It is the textbook solver's, operation for operation ((dx dx + dy dy) + dz dz, sqrt,
// (k (len - L0)) / len; no fused multiply-add), so the two solvers give bit-identical results and the
// textbook solver is an exact oracle. Subtraction, conversion, sqrt and divide are correctly rounded, so
// the generic, AVX2 and AVX-512 kernels agree bit for bit too.
//
// Generic kernel: auto-vectorised for the baseline ISA.
[[gnu::always_inline]] inline void spring_forces_generic(const double* __restrict x, const double* __restrict y,
                                                       const double* __restrict z, const float* __restrict rest,
                                                       int offset, int begin, int end, float k,
                                                       const SpringCurve& curve, float* __restrict fx,
                                                       float* __restrict fy, float* __restrict fz) {
    for (int i = begin; i < end; ++i) {
        const float dx = static_cast<float>(x[i + offset] - x[i]);
        const float dy = static_cast<float>(y[i + offset] - y[i]);
        const float dz = static_cast<float>(z[i + offset] - z[i]);
        const float length = std::sqrt(dx * dx + dy * dy + dz * dz);
        const float stretched = k * curve.stretch_term(length - rest[i], rest[i]) / length;
        const float s = rest[i] == 0.0f ? k : (length > 1e-12f ? stretched : 0.0f);
        fx[i - begin] = s * dx;
        fy[i - begin] = s * dy;
        fz[i - begin] = s * dz;
    }
}

// The first n of eight lanes (0 < n < 8) as AVX2's masked loads and stores take them: all bits set in a lane
// that is in, none in one that is out.
[[gnu::always_inline]] __attribute__((target("avx2,fma"))) inline __m256i first_lanes8(int n) {
    return _mm256_cmpgt_epi32(_mm256_set1_epi32(n), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
}

// Eight springs from their differences: the AVX2 kernel's float arithmetic (forces16 is the same in 512-bit
// vectors). With `tail` (a run's last 1 to 7 springs) the rest lengths are read and the forces written in
// its lanes only; the others compute on zeros and are dropped.
[[gnu::always_inline]] __attribute__((target("avx2,fma"))) inline void forces8(__m256 dx, __m256 dy, __m256 dz,
                                                                                const float* rest, float k,
                                                                                const SpringCurve& curve,
                                                                                float* fx, float* fy, float* fz,
                                                                                const __m256i* tail = nullptr) {
    const __m256 vk = _mm256_set1_ps(k), tiny = _mm256_set1_ps(1e-12f), zero = _mm256_setzero_ps();
    const __m256 r2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                    _mm256_mul_ps(dz, dz));
    const __m256 length = _mm256_sqrt_ps(r2);
    const __m256 l0 = tail ? _mm256_maskload_ps(rest, *tail) : _mm256_loadu_ps(rest);
    const __m256 e = _mm256_sub_ps(length, l0);
    __m256 t = e;  // SpringCurve::stretch_term, lane by lane
    for (std::uint32_t j = 0; j < curve.knots; ++j) {
        const __m256 over = _mm256_sub_ps(e, _mm256_mul_ps(l0, _mm256_set1_ps(curve.strain[j])));
        t = _mm256_blendv_ps(t, _mm256_add_ps(t, _mm256_mul_ps(_mm256_set1_ps(curve.gain[j]), over)),
                             _mm256_cmp_ps(over, zero, _CMP_GT_OQ));
    }
    const __m256 stretched = _mm256_div_ps(_mm256_mul_ps(vk, t), length);
    const __m256 apart = _mm256_blendv_ps(zero, stretched, _mm256_cmp_ps(length, tiny, _CMP_GT_OQ));
    const __m256 s = _mm256_blendv_ps(apart, vk, _mm256_cmp_ps(l0, zero, _CMP_EQ_OQ));
    if (tail) {
        _mm256_maskstore_ps(fx, *tail, _mm256_mul_ps(s, dx));
        _mm256_maskstore_ps(fy, *tail, _mm256_mul_ps(s, dy));
        _mm256_maskstore_ps(fz, *tail, _mm256_mul_ps(s, dz));
    } else {
        _mm256_storeu_ps(fx, _mm256_mul_ps(s, dx));
        _mm256_storeu_ps(fy, _mm256_mul_ps(s, dy));
        _mm256_storeu_ps(fz, _mm256_mul_ps(s, dz));
    }
}

// Four doubles from p, or only the lanes of `mask` (first_lanes8's halves; the others read as zero).
[[gnu::always_inline]] __attribute__((target("avx2,fma"))) inline __m256d load4(const double* p, const __m256i* mask) {
    return mask ? _mm256_maskload_pd(p, *mask) : _mm256_loadu_pd(p);
}
// A first_lanes8 mask's halves as masks of four doubles (lanes 0-3 and 4-7).
struct DoubleHalves {
    __m256i half[2];
};
[[gnu::always_inline]] __attribute__((target("avx2,fma"))) inline DoubleHalves double_halves(__m256i lanes) {
    return {{_mm256_cvtepi32_epi64(_mm256_castsi256_si128(lanes)),
             _mm256_cvtepi32_epi64(_mm256_extracti128_si256(lanes, 1))}};
}

// Eight differences p[i + offset] - p[i] in double, rounded to float: two 4-wide halves with AVX2 (with
// `halves`, double_halves' masks, only their lanes are read), ...
[[gnu::always_inline]] __attribute__((target("avx2,fma"))) inline __m256 difference8_avx2(
    const double* p, int i, int offset, const DoubleHalves* halves = nullptr) {
    const __m256i* m0 = halves ? &halves->half[0] : nullptr;
    const __m256i* m1 = halves ? &halves->half[1] : nullptr;
    const __m128 lo = _mm256_cvtpd_ps(_mm256_sub_pd(load4(p + i + offset, m0), load4(p + i, m0)));
    const __m128 hi = _mm256_cvtpd_ps(_mm256_sub_pd(load4(p + i + offset + 4, m1), load4(p + i + 4, m1)));
    return _mm256_insertf128_ps(_mm256_castps128_ps256(lo), hi, 1);
}
// Eight doubles from p, or only the `lanes` (the others read as zero).
[[gnu::always_inline]] __attribute__((target("avx512f,avx512vl,avx2,fma"))) inline __m512d load8(const double* p,
                                                                                                  __mmask8 lanes) {
    return lanes == 0xFF ? _mm512_loadu_pd(p) : _mm512_maskz_loadu_pd(lanes, p);
}
// ... one 8-wide subtraction and conversion with AVX-512; with `lanes` less than all eight, only those lanes'
// positions are read (the others are zero).
[[gnu::always_inline]] __attribute__((target("avx512f,avx512vl,avx2,fma"))) inline __m256 difference8_avx512(
    const double* p, int i, int offset, __mmask8 lanes = 0xFF) {
    // maskz with all lanes: _mm512_cvtpd_ps itself trips GCC 12's -Wmaybe-uninitialized in its header.
    return _mm512_maskz_cvtpd_ps(0xFF, _mm512_sub_pd(load8(p + i + offset, lanes), load8(p + i, lanes)));
}

// The AVX2 kernel: eight springs at a time, the last 1 to 7 in masked lanes.
__attribute__((target("avx2,fma"))) void spring_forces_avx2(const double* x, const double* y, const double* z,
                                                             const float* rest, int offset, int begin, int end,
                                                             float k, const SpringCurve& curve, float* fx, float* fy,
                                                             float* fz) {
    int i = begin;
    for (; i + 8 <= end; i += 8) {
        forces8(difference8_avx2(x, i, offset), difference8_avx2(y, i, offset), difference8_avx2(z, i, offset),
                rest + i, k, curve, fx + (i - begin), fy + (i - begin), fz + (i - begin));
    }
    if (i < end) {  // the last 1 to 7 springs, in masked lanes
        const __m256i lanes = first_lanes8(end - i);
        const DoubleHalves halves = double_halves(lanes);
        forces8(difference8_avx2(x, i, offset, &halves), difference8_avx2(y, i, offset, &halves),
                difference8_avx2(z, i, offset, &halves), rest + i, k, curve, fx + (i - begin), fy + (i - begin),
                fz + (i - begin), &lanes);
    }
}
// Sixteen springs from their differences: forces8's arithmetic, operation for operation, in 512-bit vectors
// (the square root and the divide, which bound the kernel, then take half the instructions). With `lanes`
// less than all sixteen (a run's last springs) the rest lengths are read and the forces written in those
// lanes only; the others compute on zeros and are dropped.
[[gnu::always_inline]] __attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma"))) inline void forces16(
    __m512 dx, __m512 dy, __m512 dz, const float* rest, float k, const SpringCurve& curve, float* fx, float* fy,
    float* fz, __mmask16 lanes = 0xFFFF) {
    const __m512 vk = _mm512_set1_ps(k), tiny = _mm512_set1_ps(1e-12f), zero = _mm512_setzero_ps();
    const __m512 r2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)),
                                    _mm512_mul_ps(dz, dz));
    const __m512 length = _mm512_maskz_sqrt_ps(0xFFFF, r2);  // maskz: the unmasked form trips -Wmaybe-uninitialized
    const __m512 l0 = lanes == 0xFFFF ? _mm512_loadu_ps(rest) : _mm512_maskz_loadu_ps(lanes, rest);
    const __m512 e = _mm512_sub_ps(length, l0);
    __m512 t = e;  // SpringCurve::stretch_term, lane by lane
    for (std::uint32_t j = 0; j < curve.knots; ++j) {
        const __m512 over = _mm512_sub_ps(e, _mm512_mul_ps(l0, _mm512_set1_ps(curve.strain[j])));
        t = _mm512_mask_add_ps(t, _mm512_cmp_ps_mask(over, zero, _CMP_GT_OQ), t,
                               _mm512_mul_ps(_mm512_set1_ps(curve.gain[j]), over));
    }
    const __m512 stretched = _mm512_div_ps(_mm512_mul_ps(vk, t), length);
    const __m512 apart = _mm512_maskz_mov_ps(_mm512_cmp_ps_mask(length, tiny, _CMP_GT_OQ), stretched);
    const __m512 s = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(l0, zero, _CMP_EQ_OQ), apart, vk);
    if (lanes == 0xFFFF) {
        _mm512_storeu_ps(fx, _mm512_mul_ps(s, dx));
        _mm512_storeu_ps(fy, _mm512_mul_ps(s, dy));
        _mm512_storeu_ps(fz, _mm512_mul_ps(s, dz));
    } else {
        _mm512_mask_storeu_ps(fx, lanes, _mm512_mul_ps(s, dx));
        _mm512_mask_storeu_ps(fy, lanes, _mm512_mul_ps(s, dy));
        _mm512_mask_storeu_ps(fz, lanes, _mm512_mul_ps(s, dz));
    }
}
// Sixteen differences: two 8-wide subtractions and conversions, joined. With `lanes` less than all sixteen,
// only those lanes' positions are read (the others are zero).
[[gnu::always_inline]] __attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma"))) inline __m512 difference16_avx512(
    const double* p, int i, int offset, __mmask16 lanes = 0xFFFF) {
    return _mm512_insertf32x8(
        _mm512_castps256_ps512(difference8_avx512(p, i, offset, static_cast<__mmask8>(lanes))),
        difference8_avx512(p, i + 8, offset, static_cast<__mmask8>(lanes >> 8)), 1);
}

__attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma"))) void spring_forces_avx512(
    const double* x, const double* y, const double* z, const float* rest, int offset, int begin, int end, float k,
    const SpringCurve& curve, float* fx, float* fy, float* fz) {
    int i = begin;
    for (; i + 16 <= end; i += 16) {
        forces16(difference16_avx512(x, i, offset), difference16_avx512(y, i, offset),
                 difference16_avx512(z, i, offset), rest + i, k, curve, fx + (i - begin), fy + (i - begin),
                 fz + (i - begin));
    }
    if (i < end) {  // the last 1 to 15 springs, in masked lanes
        const auto lanes = static_cast<__mmask16>((1u << (end - i)) - 1u);
        forces16(difference16_avx512(x, i, offset, lanes), difference16_avx512(y, i, offset, lanes),
                 difference16_avx512(z, i, offset, lanes), rest + i, k, curve, fx + (i - begin), fy + (i - begin),
                 fz + (i - begin), lanes);
    }
}

// Bend forces of one run of bends from i along `offset`: e = k float((x_i - x_m) + (x_b - x_m)), m = i + offset,
// b = i + 2 offset, the second difference taken in double and rounded once, as the textbook's
// bend_difference; the particles then get -e, 2 e, -e (row_force).
[[gnu::always_inline]] inline void bend_forces_generic(const double* __restrict x, const double* __restrict y,
                                                     const double* __restrict z, int offset, int begin, int end,
                                                     float k, float* __restrict fx, float* __restrict fy,
                                                     float* __restrict fz) {
    for (int i = begin; i < end; ++i) {
        const int m = i + offset, b = i + 2 * offset;
        fx[i - begin] = k * static_cast<float>((x[i] - x[m]) + (x[b] - x[m]));
        fy[i - begin] = k * static_cast<float>((y[i] - y[m]) + (y[b] - y[m]));
        fz[i - begin] = k * static_cast<float>((z[i] - z[m]) + (z[b] - z[m]));
    }
}
[[gnu::always_inline]] __attribute__((target("avx2,fma"))) inline __m128 second_difference4_avx2(
    const double* p, int i, int offset, const __m256i* mask) {
    const __m256d m = load4(p + i + offset, mask);
    return _mm256_cvtpd_ps(_mm256_add_pd(_mm256_sub_pd(load4(p + i, mask), m),
                                         _mm256_sub_pd(load4(p + i + 2 * offset, mask), m)));
}
// Eight bends from i; with `tail` (first_lanes8's mask of a run's last 1 to 7), only its lanes are read and
// written.
[[gnu::always_inline]] __attribute__((target("avx2,fma"))) inline void bends8_avx2(const double* const p[3], int i,
                                                                                   int offset, __m256 vk,
                                                                                   float* const out[3],
                                                                                   const __m256i* tail = nullptr) {
    const DoubleHalves halves = tail ? double_halves(*tail) : DoubleHalves{};
    const __m256i* m0 = tail ? &halves.half[0] : nullptr;
    const __m256i* m1 = tail ? &halves.half[1] : nullptr;
    for (int c = 0; c < 3; ++c) {
        const __m256 d = _mm256_mul_ps(vk, _mm256_insertf128_ps(
                                               _mm256_castps128_ps256(second_difference4_avx2(p[c], i, offset, m0)),
                                               second_difference4_avx2(p[c], i + 4, offset, m1), 1));
        if (tail) {
            _mm256_maskstore_ps(out[c], *tail, d);
        } else {
            _mm256_storeu_ps(out[c], d);
        }
    }
}
__attribute__((target("avx2,fma"))) void bend_forces_avx2(const double* x, const double* y, const double* z,
                                                           int offset, int begin, int end, float k, float* fx,
                                                           float* fy, float* fz) {
    const __m256 vk = _mm256_set1_ps(k);
    const double* const p[3] = {x, y, z};
    int i = begin;
    for (; i + 8 <= end; i += 8) {
        float* const out[3] = {fx + (i - begin), fy + (i - begin), fz + (i - begin)};
        bends8_avx2(p, i, offset, vk, out);
    }
    if (i < end) {  // the last 1 to 7 bends, in masked lanes
        const __m256i lanes = first_lanes8(end - i);
        float* const out[3] = {fx + (i - begin), fy + (i - begin), fz + (i - begin)};
        bends8_avx2(p, i, offset, vk, out, &lanes);
    }
}
// Eight bends from i with AVX-512; with `lanes` less than all eight (a run's last 1 to 7), only those lanes
// are read and written.
[[gnu::always_inline]] __attribute__((target("avx512f,avx512vl,avx2,fma"))) inline void bends8_avx512(
    const double* const p[3], int i, int offset, __m256 vk, float* const out[3], __mmask8 lanes = 0xFF) {
    for (int c = 0; c < 3; ++c) {
        const __m512d m = load8(p[c] + i + offset, lanes);
        const __m512d d =
            _mm512_add_pd(_mm512_sub_pd(load8(p[c] + i, lanes), m), _mm512_sub_pd(load8(p[c] + i + 2 * offset, lanes), m));
        const __m256 e = _mm256_mul_ps(vk, _mm512_maskz_cvtpd_ps(0xFF, d));
        if (lanes == 0xFF) {
            _mm256_storeu_ps(out[c], e);
        } else {
            _mm256_mask_storeu_ps(out[c], lanes, e);
        }
    }
}
__attribute__((target("avx512f,avx512vl,avx2,fma"))) void bend_forces_avx512(const double* x, const double* y,
                                                                             const double* z, int offset, int begin,
                                                                             int end, float k, float* fx, float* fy,
                                                                             float* fz) {
    const __m256 vk = _mm256_set1_ps(k);
    const double* const p[3] = {x, y, z};
    int i = begin;
    for (; i + 8 <= end; i += 8) {
        float* const out[3] = {fx + (i - begin), fy + (i - begin), fz + (i - begin)};
        bends8_avx512(p, i, offset, vk, out);
    }
    if (i < end) {  // the last 1 to 7 bends, in masked lanes
        float* const out[3] = {fx + (i - begin), fy + (i - begin), fz + (i - begin)};
        bends8_avx512(p, i, offset, vk, out, static_cast<__mmask8>((1u << (end - i)) - 1u));
    }
}

// The running bounds of a band's motion in eight lanes per component (lane j: columns j, j + 8, ...), so a
// row widens them with whole vectors and no reduction; the lanes are reduced once, at the end of the band.
// Layout (FastSolver::Scratch::motion_lanes): lo of component k at [8 k, 8 k + 8), hi at [24 + 8 k, ...).
void reset_lanes(double* lanes) {
    std::fill(lanes, lanes + 24, INFINITY);
    std::fill(lanes + 24, lanes + 48, -INFINITY);
}

// NaN values are left out, as a pass over the motions leaves them (include_motion): each bound is taken as
// MINPD and MAXPD take it, the new value first, and they return their second operand, the running bound,
// when either is NaN. The lanes never hold NaN, so where they are joined the order does not matter.
void widen_tail(const double* m, int c, int n, double* lo, double* hi) {
    for (; c < n; ++c) {
        lo[c & 7] = m[c] < lo[c & 7] ? m[c] : lo[c & 7];
        hi[c & 7] = m[c] > hi[c & 7] ? m[c] : hi[c & 7];
    }
}

MotionBounds reduce_lanes(const double* lanes) {
    MotionBounds b;
    for (int k = 0; k < 3; ++k) {
        const double* lo = lanes + 8 * k;
        const double* hi = lanes + 24 + 8 * k;
        b.lo[k] = lo[0], b.hi[k] = hi[0];
        for (int j = 1; j < 8; ++j) {
            b.lo[k] = b.lo[k] < lo[j] ? b.lo[k] : lo[j];
            b.hi[k] = b.hi[k] > hi[j] ? b.hi[k] : hi[j];
        }
    }
    b.empty = false;
    return b;
}

// Asked of the CPU once, on first use.
FastKernel cpu_best_kernel() {
    static const FastKernel best = [] {
        __builtin_cpu_init();
        if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) return FastKernel::Generic;
        if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
            __builtin_cpu_supports("avx512dq")) {
            return FastKernel::Avx512;
        }
        return FastKernel::Avx2;
    }();
    return best;
}

// Set by use_kernel: the tests run every kernel the CPU has.
std::optional<FastKernel> kernel_forced;

FastKernel kernel_in_use() { return kernel_forced ? *kernel_forced : cpu_best_kernel(); }

}  // namespace

FastKernel FastSolver::best_kernel() { return cpu_best_kernel(); }
FastKernel FastSolver::kernel() { return kernel_in_use(); }

const char* FastSolver::kernel_name(FastKernel kernel) {
    switch (kernel) {
        case FastKernel::Avx512: return "avx512";
        case FastKernel::Avx2: return "avx2+fma";
        case FastKernel::Generic: return "generic";
    }
    return "generic";
}

FastKernel FastSolver::use_kernel(FastKernel kernel) {
    const FastKernel was = kernel_in_use();
    kernel_forced = static_cast<int>(kernel) <= static_cast<int>(cpu_best_kernel()) ? std::optional(kernel)
                                                                                     : std::nullopt;
    return was;
}

std::optional<FastSolver> FastSolver::for_topology(const Topology& t) {
    if (t.rows < 1 || t.cols < 1) return std::nullopt;
    FastSolver solver(t.rows, t.cols);
    const std::size_t n = static_cast<std::size_t>(t.rows) * t.cols;
    // Missing springs keep rest length NaN until checked below; every in-grid slot must be filled by
    // exactly one spring for the sweep to be the same model as the spring list.
    for (auto& r : solver.rest_) r.assign(n, NAN);
    std::array<std::vector<float>, 6> weight;
    for (auto& w : weight) w.assign(n, 1.0f);
    // Places the element from `start` along (dr, dc) in its direction; false when none fits or it is a duplicate.
    auto place = [&](SpringKind kind, std::size_t start, int dr, int dc, float rest, float w) {
        int exponent = 0;
        if (w != 0.0f && std::frexp(w, &exponent) != 0.5f) return false;  // not a power of two: not exact
        for (int d = 0; d < 6; ++d) {
            const Direction& dir = kDirections[d];
            if (dir.kind != kind || dir.dr != dr || dir.dc != dc) continue;
            if (!std::isnan(solver.rest_[d][start])) return false;  // a duplicate
            solver.rest_[d][start] = rest;
            weight[d][start] = w;
            solver.present_[d] = true;
            return true;
        }
        return false;
    };
    auto grid_of = [&](std::uint32_t i) { return std::pair{static_cast<int>(i) / t.cols, static_cast<int>(i) % t.cols}; };
    for (const Spring& s : t.springs) {
        if (s.a >= n || s.b >= n) return std::nullopt;
        const auto [ra, ca] = grid_of(s.a);
        const auto [rb, cb] = grid_of(s.b);
        // Either end may be listed first.
        if (!place(s.kind, s.a, rb - ra, cb - ca, s.rest_length, s.weight) &&
            !place(s.kind, s.b, ra - rb, ca - cb, s.rest_length, s.weight)) {
            return std::nullopt;
        }
    }
    if (!t.bends.empty()) {
        if (solver.present_[4] || solver.present_[5]) return std::nullopt;  // bending springs and bends both
        solver.bends_ = true;
    }
    for (const Bend& b : t.bends) {
        if (b.a >= n || b.m >= n || b.b >= n) return std::nullopt;
        const auto [ra, ca] = grid_of(b.a);
        const auto [rm, cm] = grid_of(b.m);
        const auto [rb, cb] = grid_of(b.b);
        // A bend is stored as its two-apart direction from a; its middle must lie halfway.
        if (2 * rm != ra + rb || 2 * cm != ca + cb) return std::nullopt;
        if (!place(SpringKind::Bending, b.a, rb - ra, cb - ca, 0.0f, b.weight) &&
            !place(SpringKind::Bending, b.b, ra - rb, ca - cb, 0.0f, b.weight)) {
            return std::nullopt;
        }
    }
    for (int d = 0; d < 6; ++d) {
        const Direction& dir = kDirections[d];
        // A slot without an element in a direction that has some (a grid slot outside a disc, or an edge the
        // shape leaves out) gets weight 0: the sweep computes it and scales it to nothing.
        for (std::size_t i = 0; i < n; ++i) {
            if (std::isnan(solver.rest_[d][i])) solver.rest_[d][i] = 0.0f, weight[d][i] = 0.0f;
        }
        // Per row: the largest weight scales the row's k, the other columns' forces are scaled by their
        // weight over it (powers of two: exact) afterwards.
        const int c0 = first_column(dir), c1 = end_column(dir, t.cols);
        solver.row_weight_[d].assign(t.rows, 1.0f);
        solver.fix_begin_[d].assign(t.rows + 1, 0);
        for (int r = 0; r < t.rows; ++r) {
            solver.fix_begin_[d][r] = static_cast<int>(solver.fixes_[d].size());
            if (!solver.present_[d] || r + dir.dr >= t.rows || c1 <= c0) continue;
            const float* w = weight[d].data() + static_cast<std::size_t>(r) * t.cols;
            const float base = *std::max_element(w + c0, w + c1);
            solver.row_weight_[d][r] = base;
            if (base == 0.0f) continue;
            for (int c = c0; c < c1; ++c) {
                if (w[c] != base) solver.fixes_[d].emplace_back(c, w[c] / base);
            }
        }
        solver.fix_begin_[d][t.rows] = static_cast<int>(solver.fixes_[d].size());
    }
    return solver;
}

int FastSolver::effective_threads(int requested) const {
    const int wanted = requested > 0 ? requested : WorkTeam::cores();
    return std::clamp(std::min(wanted, rows_ / 8), 1, WorkTeam::kMaxThreads);
}

int FastSolver::band_count(int threads) const {
    // A few bands per thread, so a thread that is descheduled holds up one small band at most while the others
    // take the rest (work_team.hpp); each band at least 8 rows.
    return threads <= 1 ? 1 : std::clamp(std::min(rows_ / 8, kBandsPerThread * threads), threads, kMaxBands);
}

void FastSolver::step(State& state, const SimulationSettings& settings, unsigned kinds, const Vec3Array* external,
                      double h, double damping, std::vector<Box>* row_boxes, MotionBounds* motion_bounds, BlockBounds bounds,
                      Box* band_unions) {
    const unsigned spring_mask = (kinds & 7u) | (bends_ ? kBendsBit : 0u);
    const int threads = effective_threads(settings.solver.threads);
    const int bands = band_count(threads);
    const std::size_t row_floats = 18 * spring_row_stride(cols_);
    // Buffers and the band layout are set up again only when the band count changes.
    if (bands != bands_) {
        bands_ = bands;
        scratch_.resize(bands);
        for (Scratch& s : scratch_) s.window.assign(3 * row_floats, 0.0f);
        zeros_.assign(row_floats, 0.0f);
        boundary_slot_.assign(rows_, -1);
        no_boundary_.assign(rows_, -1);
        boundary_.assign(static_cast<std::size_t>(2 * bands) * row_floats, 0.0f);
        for (int b = 1; b < bands; ++b) {
            const int begin = band_begin(b, bands);
            boundary_slot_[begin - 2] = 2 * b;
            boundary_slot_[begin - 1] = 2 * b + 1;
        }
        team_.reset();
    }
    if (row_boxes) row_boxes->resize(static_cast<std::size_t>(rows_) * blocks_per_row(cols_));
    const SweepSettings sweep_settings{settings, spring_mask, external, h, damping, row_boxes ? row_boxes->data() : nullptr,
                                       bounds, motion_bounds != nullptr};
    // With solver.threads = 0 the team may be set aside for this substep (team_choice.hpp).
    const bool automatic = settings.solver.threads == 0 && threads > 1;
    const bool single = threads == 1 || (automatic && team_.next_is_single());
    if (motion_bounds) *motion_bounds = MotionBounds{};
    const auto give_unions = [&](int used) {
        if (!band_unions || !row_boxes) return;
        for (int b = 0; b < kMaxBands; ++b) band_unions[b] = b < used ? scratch_[b].box_union : Box{};
    };
    if (single) {
        const auto start = std::chrono::steady_clock::now();
        sweep(state, sweep_settings, 0, rows_, scratch_[0], no_boundary_);
        if (automatic) team_.record(true, std::chrono::steady_clock::now() - start);
        if (motion_bounds) *motion_bounds = reduce_lanes(scratch_[0].motion_lanes.data());
        state.substep = h;
        last_bands_ = 1;
        last_threads_ = 1;
        give_unions(1);
        return;
    }
    const auto start = std::chrono::steady_clock::now();
    WorkTeam& team = WorkTeam::shared();
    // Phase 1: the two spring rows above each band's first row read that band's first rows, which its sweep
    // will overwrite; compute them while every position is still the old one.
    team.run(threads, bands - 1, [&](int b, int) {
        const int next = band_begin(b + 1, bands);
        for (int r : {next - 2, next - 1}) {
            spring_row(state, settings.springs, spring_mask, r,
                       boundary_.data() + static_cast<std::size_t>(boundary_slot_[r]) * row_floats);
        }
    });
    // Phase 2: the bands' sweeps, each on its own rows.
    team.run(threads, bands, [&](int b, int) {
        sweep(state, sweep_settings, band_begin(b, bands), band_begin(b + 1, bands), scratch_[b], boundary_slot_);
    });
    if (automatic) team_.record(false, std::chrono::steady_clock::now() - start);
    last_bands_ = bands;
    last_threads_ = threads;
    give_unions(bands);
    for (int b = 0; motion_bounds && b < bands; ++b) {
        if (band_begin(b, bands) < band_begin(b + 1, bands)) {
            motion_bounds->include(reduce_lanes(scratch_[b].motion_lanes.data()));
        }
    }
    state.substep = h;
}

void FastSolver::for_each_band(const std::function<void(int, int, int)>& work) const {
    const int bands = last_bands_;
    if (bands <= 1) {
        work(0, 0, rows_);
        return;
    }
    WorkTeam::shared().run(last_threads_, bands,
                           [&](int b, int) { work(b, band_begin(b, bands), band_begin(b + 1, bands)); });
}

// ---- The sweep, written once and compiled twice: for AVX2 + FMA and for the baseline ISA. ----

namespace {

struct Grid {
    int rows, cols;
    const std::array<AlignedVector<float>, 6>& rest;
    const std::array<bool, 6>& present;
    const std::array<std::vector<float>, 6>& row_weight;
    const std::array<std::vector<int>, 6>& fix_begin;
    const std::array<std::vector<std::pair<int, float>>, 6>& fixes;
    std::size_t stride() const { return spring_row_stride(cols); }
    // Spring-row storage: 18 rows (direction, component) of `stride` floats, column c at [kPad + c].
    std::size_t row_floats() const { return 18 * stride(); }
};

constexpr SpringCurve kLinearCurve{};

constexpr bool kind_runs(unsigned mask, SpringKind kind) { return (mask >> static_cast<int>(kind)) & 1u; }

// Directions of a kind the plan skips are neither computed nor written: integrate_row<Mask> never reads them.
template <FastKernel K, unsigned Mask>
[[gnu::always_inline]] inline void spring_row_body(const Grid& grid, const State& state, const SpringSettings& springs,
                                                   int r, float* out) {
    const std::size_t stride = grid.stride();
    const float stiffness[6] = {springs.structural.x, springs.structural.y, springs.shear,
                                springs.shear,        springs.bending.x,    springs.bending.y};
    for (int d = 0; d < 6; ++d) {
        const Direction& dir = kDirections[d];
        if (!kind_runs(Mask, dir.kind)) continue;
        float* f = out + 3 * d * stride + kPad;  // column 0 of component x
        const int c0 = first_column(dir), c1 = end_column(dir, grid.cols);
        // Rows past the bottom and a direction the topology lacks hold zero. Columns without a spring and the
        // padding hold zero too: every spring-row buffer starts zeroed and the kernels write only [c0, c1),
        // the same columns for a direction in every row.
        const bool any = grid.present[d] && r + dir.dr < grid.rows && c1 > c0;
        if (!any) {
            std::memset(f - kPad, 0, 3 * stride * sizeof(float));
            continue;
        }
        const int row_start = r * grid.cols;
        const int offset = dir.dr * grid.cols + dir.dc;
        const float k = stiffness[d] * grid.row_weight[d][r];
        const SpringCurve& curve = d < 2 ? springs.stretch_curve[d] : kLinearCurve;
        const double* x = state.position.x.data();
        const double* y = state.position.y.data();
        const double* z = state.position.z.data();
        const int begin = row_start + c0, end = row_start + c1;
        if (d >= 4 && (Mask & kBendsBit)) {
            const int half = offset / 2;  // a bend's middle is halfway along the two-apart direction
            if constexpr (K == FastKernel::Avx512) {
                bend_forces_avx512(x, y, z, half, begin, end, k, f + c0, f + stride + c0, f + 2 * stride + c0);
            } else if constexpr (K == FastKernel::Avx2) {
                bend_forces_avx2(x, y, z, half, begin, end, k, f + c0, f + stride + c0, f + 2 * stride + c0);
            } else {
                bend_forces_generic(x, y, z, half, begin, end, k, f + c0, f + stride + c0, f + 2 * stride + c0);
            }
        } else if constexpr (K == FastKernel::Avx512) {
            spring_forces_avx512(x, y, z, grid.rest[d].data(), offset, begin, end, k, curve, f + c0, f + stride + c0,
                                 f + 2 * stride + c0);
        } else if constexpr (K == FastKernel::Avx2) {
            spring_forces_avx2(x, y, z, grid.rest[d].data(), offset, begin, end, k, curve, f + c0, f + stride + c0,
                               f + 2 * stride + c0);
        } else {
            spring_forces_generic(x, y, z, grid.rest[d].data(), offset, begin, end, k, curve, f + c0, f + stride + c0,
                                  f + 2 * stride + c0);
        }
        for (int i = grid.fix_begin[d][r]; i < grid.fix_begin[d][r + 1]; ++i) {
            const auto [c, w] = grid.fixes[d][i];
            f[c] *= w, f[stride + c] *= w, f[2 * stride + c] *= w;
        }
    }
}

// Vectors of floats and doubles in GCC's vector extensions, for the row update of each sweep:
// element-wise IEEE operations without contraction (-ffp-contract=off), so a lane computes what the scalar
// loop computes. Every function that takes or returns them is inlined into one sweep; -Wpsabi warns about
// the ABI of the templates themselves, compiled for the baseline ISA, which no call ever uses.
#pragma GCC diagnostic ignored "-Wpsabi"  // to the end of the file: GCC reports it there
using Floats16 = float __attribute__((vector_size(64)));
using Floats4 = float __attribute__((vector_size(16)));
using Floats8 = float __attribute__((vector_size(32)));
using Doubles2 = double __attribute__((vector_size(16)));
using Doubles4 = double __attribute__((vector_size(32)));
using Doubles8 = double __attribute__((vector_size(64)));
using Doubles16 = double __attribute__((vector_size(128)));
template <class V, class T>
[[gnu::always_inline]] inline V load(const T* p) {
    V v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
template <class V, class T>
[[gnu::always_inline]] inline void store(T* p, V v) {
    std::memcpy(p, &v, sizeof v);
}
// `at(p, i)` reads p[i]: one float, or a vector of them from there (the row update's vector loops below).
template <unsigned Mask, bool Ext, class At>
[[gnu::always_inline]] inline auto row_force(At at, const float* __restrict f0, const float* __restrict f1,
                                             const float* __restrict f2, const float* __restrict ext, std::size_t D,
                                             std::ptrdiff_t c) {
    decltype(at(f0, c)) f{};
    if constexpr (kind_runs(Mask, SpringKind::Structural)) {
        f = (f - at(f0, c - 1)) + at(f0, c);                  // (0,+1)
        f = (f - at(f1, D + c)) + at(f0, D + c);              // (+1,0)
    }
    if constexpr (kind_runs(Mask, SpringKind::Shear)) {
        f = (f - at(f1, 2 * D + c - 1)) + at(f0, 2 * D + c);  // (+1,+1)
        f = (f - at(f1, 3 * D + c + 1)) + at(f0, 3 * D + c);  // (+1,-1)
    }
    if constexpr (kind_runs(Mask, SpringKind::Bending) && (Mask & kBendsBit)) {
        // Bends in the textbook's order, the one starting two before the particle first: -e, +2 e, -e.
        f = ((f - at(f0, 4 * D + c - 2)) + 2.0f * at(f0, 4 * D + c - 1)) - at(f0, 4 * D + c);  // along (0,+1)
        f = ((f - at(f2, 5 * D + c)) + 2.0f * at(f1, 5 * D + c)) - at(f0, 5 * D + c);          // along (+1,0)
    } else if constexpr (kind_runs(Mask, SpringKind::Bending)) {
        f = (f - at(f0, 4 * D + c - 2)) + at(f0, 4 * D + c);  // (0,+2)
        f = (f - at(f2, 5 * D + c)) + at(f0, 5 * D + c);      // (+2,0)
    }
    if constexpr (Ext) f += at(ext, c);
    return f;
}

// Everything integrate_row reads and writes for one row, per component (x, y, z).
struct RowData {
    const float* f[3][3];  // spring rows q, q-1, q-2 (column 0) of each component
    const float* ext[3];   // external force, or null
    double* x[3];
    double* m[3];
    const float* w;
    float g[3];
};

// Row q's force, gathered from the spring rows q, q-1 and q-2 (-F on a spring's second particle, +F on its
// first), in the textbook solver's order: direction by direction, the spring ending at the particle before
// the one starting there, external force last. Then position Verlet for the row (gravity and damping
// inside), one component at a time. The force and the substep's change (f w + g) h2 are float,
// the motion and the position double, as in integrate_verlet. A pinned particle (inverse mass 0) has no
// change and zero motion, so it does not move. Every particle is read and written once.
//
// With `lanes` (the band's running bounds of the motion, reset_lanes' layout) the row's new motions widen
// them while they are still in registers, in whole vectors: column c goes to lane c mod 8, as widen_tail
// takes it, and the bounds are exact (a minimum and a maximum round nothing). The columns after the last
// whole vector widen them in a second pass (widen_tail).
template <FastKernel K, unsigned Mask, bool Ext>
[[gnu::always_inline]] inline void integrate_row(const RowData& row, int cols, std::size_t stride, double keep,
                                                 float h2, double* lanes) {
    const std::size_t D = 3 * stride;  // component rows of one spring row are 6 directions apart by 3 * stride
    const float* __restrict w = row.w;
    const auto one = [](const float* p, std::ptrdiff_t i) __attribute__((always_inline)) { return p[i]; };
    for (int comp = 0; comp < 3; ++comp) {
        const float* __restrict f0 = row.f[comp][0];
        const float* __restrict f1 = row.f[comp][1];
        const float* __restrict f2 = row.f[comp][2];
        const float* __restrict ext = row.ext[comp];
        double* __restrict x = row.x[comp];
        double* __restrict m = row.m[comp];
        const float g = row.g[comp];
        double* lo = lanes ? lanes + 8 * comp : nullptr;
        double* hi = lanes ? lanes + 24 + 8 * comp : nullptr;
        int c = 0;
        if (lanes) {
            // Column c widens lane c mod 8. Each instruction set takes vectors it has: with AVX-512 sixteen
            // floats and two eight-double halves (lanes 0-7 twice: two running bounds, joined at the end),
            // with AVX2 eight floats and two four-double halves (lanes 0-3 and 4-7), with the baseline's
            // SSE2 four floats and two two-double halves, twice (lanes 0-1, 2-3, 4-5 and 6-7). The floats are
            // converted in one vector twice their width, which GCC 12 lowers to whole conversions.
            const auto update = [&](auto change, int col, auto& low, auto& high) __attribute__((always_inline)) {
                using V = decltype(change);
                const V step = load<V>(m + col) * keep + change;
                store(m + col, step);
                store(x + col, load<V>(x + col) + step);
                low = step < low ? step : low;  // NaN left out (widen_tail)
                high = step > high ? step : high;
            };
            // The substep's changes (f w + g) h2 (0 where pinned) of the columns from `col` in a float vector
            // like `narrow`, widened to double in one vector like `wide`, twice its width.
            const auto widened_change = [&](auto narrow, auto wide, int col) __attribute__((always_inline)) {
                using F = decltype(narrow);
                using W = decltype(wide);
                const auto read = [](const float* p, std::ptrdiff_t i) __attribute__((always_inline)) {
                    return load<F>(p + i);
                };
                const F f = row_force<Mask, Ext>(read, f0, f1, f2, ext, D, col);
                const F wc = load<F>(w + col);
                const F change = wc == 0.0f ? F{} : (f * wc + g) * h2;
                return __builtin_convertvector(change, W);
            };
            if constexpr (K == FastKernel::Avx512) {
                Doubles8 lo0 = load<Doubles8>(lo), hi0 = load<Doubles8>(hi), lo1 = lo0, hi1 = hi0;
                for (; c + 16 <= cols; c += 16) {
                    const Doubles16 wide = widened_change(Floats16{}, Doubles16{}, c);
                    update(__builtin_shufflevector(wide, wide, 0, 1, 2, 3, 4, 5, 6, 7), c, lo0, hi0);
                    update(__builtin_shufflevector(wide, wide, 8, 9, 10, 11, 12, 13, 14, 15), c + 8, lo1, hi1);
                }
                store(lo, lo0 < lo1 ? lo0 : lo1), store(hi, hi0 > hi1 ? hi0 : hi1);
            } else if constexpr (K == FastKernel::Avx2) {
                Doubles4 lo0 = load<Doubles4>(lo), lo1 = load<Doubles4>(lo + 4);
                Doubles4 hi0 = load<Doubles4>(hi), hi1 = load<Doubles4>(hi + 4);
                for (; c + 8 <= cols; c += 8) {
                    const Doubles8 wide = widened_change(Floats8{}, Doubles8{}, c);
                    update(__builtin_shufflevector(wide, wide, 0, 1, 2, 3), c, lo0, hi0);
                    update(__builtin_shufflevector(wide, wide, 4, 5, 6, 7), c + 4, lo1, hi1);
                }
                store(lo, lo0), store(lo + 4, lo1), store(hi, hi0), store(hi + 4, hi1);
            } else {
                Doubles2 low[4], high[4];
                for (int j = 0; j < 4; ++j) low[j] = load<Doubles2>(lo + 2 * j), high[j] = load<Doubles2>(hi + 2 * j);
                for (; c + 8 <= cols; c += 8) {
                    for (int half = 0; half < 2; ++half) {
                        const int col = c + 4 * half;
                        const Doubles4 wide = widened_change(Floats4{}, Doubles4{}, col);
                        update(__builtin_shufflevector(wide, wide, 0, 1), col, low[2 * half], high[2 * half]);
                        update(__builtin_shufflevector(wide, wide, 2, 3), col + 2, low[2 * half + 1],
                               high[2 * half + 1]);
                    }
                }
                for (int j = 0; j < 4; ++j) store(lo + 2 * j, low[j]), store(hi + 2 * j, high[j]);
            }
        }
        for (int t = c; t < cols; ++t) {
            const float f = row_force<Mask, Ext>(one, f0, f1, f2, ext, D, t);
            const float change = w[t] == 0.0f ? 0.0f : (f * w[t] + g) * h2;  // a select: the loop vectorises
            const double step = m[t] * keep + static_cast<double>(change);
            m[t] = step;
            x[t] += step;
        }
        if (lanes) widen_tail(m, c, cols, lo, hi);
    }
}

// Everything the sweep of one band reads besides the state.
struct SweepInput {
    const Grid& grid;
    const AlignedVector<float>& boundary;
    const std::vector<int>& boundary_slot;
    const SimulationSettings& settings;
    const Vec3Array* external;
    double h;
    double damping;
    Box* row_boxes;  // the boxes of each row's blocks after its update (block_starts), or null
    BlockBounds bounds;  // what of each box
    float* window;
    const float* zeros;
    double* motion_lanes;  // the running bounds of the band's motion (8 lanes), or null when not asked for
};

template <FastKernel K, unsigned Mask>
[[gnu::always_inline]] inline void sweep_body(const SweepInput& in, State& state, int begin, int end) {
    const Grid& grid = in.grid;
    const std::size_t stride = grid.stride();
    const std::size_t row_floats = grid.row_floats();
    const auto [keep, h2] = verlet_coefficients(in.damping, in.h);
    const glm::vec3 g = in.settings.forces.gravity;
    // The spring rows r, r-1, r-2: in the rolling window, in the shared boundary storage, or zero above row 0.
    const float* spring_rows[3] = {in.zeros, in.zeros, in.zeros};
    if (in.motion_lanes) reset_lanes(in.motion_lanes);
    for (int r = std::max(begin - 2, 0); r < end; ++r) {
        const float* current;
        if (in.boundary_slot[r] >= 0) {
            current = in.boundary.data() + static_cast<std::size_t>(in.boundary_slot[r]) * row_floats;
        } else {
            float* slot = in.window + static_cast<std::size_t>(r % 3) * row_floats;
            spring_row_body<K, Mask>(grid, state, in.settings.springs, r, slot);
            current = slot;
        }
        spring_rows[2] = spring_rows[1];
        spring_rows[1] = spring_rows[0];
        spring_rows[0] = current;
        if (r < begin) continue;
        // Row r is complete: gather its forces and integrate it in place. No later spring row reads row r,
        // so the collision stage may move it after the sweep.
        const std::size_t i0 = static_cast<std::size_t>(r) * grid.cols;
        RowData row{};
        for (int comp = 0; comp < 3; ++comp) {
            const std::size_t at = comp * stride + kPad;
            for (int k = 0; k < 3; ++k) row.f[comp][k] = spring_rows[k] + at;
        }
        row.x[0] = state.position.x.data() + i0, row.x[1] = state.position.y.data() + i0, row.x[2] = state.position.z.data() + i0;
        row.m[0] = state.motion.x.data() + i0, row.m[1] = state.motion.y.data() + i0, row.m[2] = state.motion.z.data() + i0;
        row.w = state.inverse_mass.data() + i0;
        row.g[0] = g.x, row.g[1] = g.y, row.g[2] = g.z;
        if (in.external) {
            row.ext[0] = in.external->x.data() + i0, row.ext[1] = in.external->y.data() + i0, row.ext[2] = in.external->z.data() + i0;
            integrate_row<K, Mask, true>(row, grid.cols, stride, keep, h2, in.motion_lanes);
        } else {
            integrate_row<K, Mask, false>(row, grid.cols, stride, keep, h2, in.motion_lanes);
        }
        // The row is still in L1: the boxes of its blocks for the collision broad phase cost one more pass.
        if (in.row_boxes) {
            row_block_bounds(state.position, i0, grid.cols, in.row_boxes + static_cast<std::size_t>(r) * blocks_per_row(grid.cols),
                             in.bounds);
        }
    }
}

// One compiled sweep per spring-kind mask and instruction set, picked from a table at run time. The AVX-512
// one also runs the row update and the differences with 512-bit vectors (8 doubles at a time): element-wise
// IEEE operations without contraction, bit-identical to the others.
#define CLOTHSIM_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma,prefer-vector-width=512")))
#define CLOTHSIM_AVX2 __attribute__((target("avx2,fma")))
template <unsigned Mask>
CLOTHSIM_AVX512 void spring_row_avx512(const Grid& grid, const State& state, const SpringSettings& springs, int r,
                                       float* out) {
    spring_row_body<FastKernel::Avx512, Mask>(grid, state, springs, r, out);
}
template <unsigned Mask>
CLOTHSIM_AVX2 void spring_row_avx2(const Grid& grid, const State& state, const SpringSettings& springs, int r,
                                   float* out) {
    spring_row_body<FastKernel::Avx2, Mask>(grid, state, springs, r, out);
}
template <unsigned Mask>
void spring_row_generic(const Grid& grid, const State& state, const SpringSettings& springs, int r, float* out) {
    spring_row_body<FastKernel::Generic, Mask>(grid, state, springs, r, out);
}
template <unsigned Mask>
CLOTHSIM_AVX512 void sweep_avx512(const SweepInput& in, State& state, int begin, int end) {
    sweep_body<FastKernel::Avx512, Mask>(in, state, begin, end);
}
template <unsigned Mask>
CLOTHSIM_AVX2 void sweep_avx2(const SweepInput& in, State& state, int begin, int end) {
    sweep_body<FastKernel::Avx2, Mask>(in, state, begin, end);
}
template <unsigned Mask>
void sweep_generic(const SweepInput& in, State& state, int begin, int end) {
    sweep_body<FastKernel::Generic, Mask>(in, state, begin, end);
}
#undef CLOTHSIM_AVX512
#undef CLOTHSIM_AVX2

using SpringRowFn = void (*)(const Grid&, const State&, const SpringSettings&, int, float*);
using SweepFn = void (*)(const SweepInput&, State&, int, int);
template <std::size_t... M>
constexpr std::array<SpringRowFn, 16> spring_row_table(FastKernel kernel, std::index_sequence<M...>) {
    switch (kernel) {
        case FastKernel::Avx512: return {spring_row_avx512<M>...};
        case FastKernel::Avx2: return {spring_row_avx2<M>...};
        case FastKernel::Generic: break;
    }
    return {spring_row_generic<M>...};
}
template <std::size_t... M>
constexpr std::array<SweepFn, 16> sweep_table(FastKernel kernel, std::index_sequence<M...>) {
    switch (kernel) {
        case FastKernel::Avx512: return {sweep_avx512<M>...};
        case FastKernel::Avx2: return {sweep_avx2<M>...};
        case FastKernel::Generic: break;
    }
    return {sweep_generic<M>...};
}

}  // namespace

void FastSolver::spring_row(const State& state, const SpringSettings& springs, unsigned mask, int r, float* out) const {
    const Grid grid{rows_, cols_, rest_, present_, row_weight_, fix_begin_, fixes_};
    spring_row_table(kernel_in_use(), std::make_index_sequence<16>())[mask & 15u](grid, state, springs, r, out);
}

void FastSolver::sweep(State& state, const SweepSettings& sweep, int begin, int end, Scratch& scratch,
                       const std::vector<int>& boundary_slot) {
    const Grid grid{rows_, cols_, rest_, present_, row_weight_, fix_begin_, fixes_};
    const SweepInput in{grid, boundary_, boundary_slot, sweep.settings, sweep.external, sweep.h, sweep.damping,
                        sweep.row_boxes, sweep.bounds, scratch.window.data(), zeros_.data(),
                        sweep.motion_bounds ? scratch.motion_lanes.data() : nullptr};
    sweep_table(kernel_in_use(), std::make_index_sequence<16>())[sweep.mask & 15u](in, state, begin, end);
    if (sweep.row_boxes) {  // while this band's boxes are in this core's cache
        const std::size_t per_row = blocks_per_row(cols_);
        scratch.box_union = union_of(sweep.row_boxes + static_cast<std::size_t>(begin) * per_row,
                                     static_cast<std::size_t>(end - begin) * per_row);
    }
}

}  // namespace clothsim
