#include "collision/broad_phase.hpp"

#include "integrators/fast_solver.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <immintrin.h>

#include <algorithm>
#include <array>

namespace clothsim {
namespace {

// GCC does not vectorise a min/max reduction without -ffinite-math-only, so the AVX2 loop is written out.
// _mm256_min_pd(x, lo) returns lo when x is NaN, which leaves NaN coordinates out, as the scalar loop does.
__attribute__((target("avx2"))) void bounds_avx2(const double* v, std::size_t n, double& lo, double& hi) {
    __m256d l = _mm256_set1_pd(INFINITY), h = _mm256_set1_pd(-INFINITY);
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const __m256d x = _mm256_loadu_pd(v + i);
        l = _mm256_min_pd(x, l);
        h = _mm256_max_pd(x, h);
    }
    alignas(32) double ls[4], hs[4];
    _mm256_store_pd(ls, l);
    _mm256_store_pd(hs, h);
    for (int k = 0; k < 4; ++k) {
        lo = std::min(lo, ls[k]);
        hi = std::max(hi, hs[k]);
    }
    for (; i < n; ++i) {
        lo = v[i] < lo ? v[i] : lo;
        hi = hi < v[i] ? v[i] : hi;
    }
}

void bounds_generic(const double* v, std::size_t n, double& lo, double& hi) {
    for (std::size_t i = 0; i < n; ++i) {
        lo = v[i] < lo ? v[i] : lo;
        hi = hi < v[i] ? v[i] : hi;
    }
}

__attribute__((target("avx2"))) inline double hmin(__m256d v) {
    __m128d m = _mm_min_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
    m = _mm_min_sd(m, _mm_unpackhi_pd(m, m));
    return _mm_cvtsd_f64(m);
}
__attribute__((target("avx2"))) inline double hmax(__m256d v) {
    __m128d m = _mm_max_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
    m = _mm_max_sd(m, _mm_unpackhi_pd(m, m));
    return _mm_cvtsd_f64(m);
}

// One full block's box (16 particles from `v`, per axis): four vectors per axis and a shuffle reduction.
__attribute__((target("avx2"))) inline void block_bounds_avx2(const double* const axes[3], std::size_t c, Box& out) {
    for (int a = 0; a < 3; ++a) {
        const double* v = axes[a] + c;
        // _mm256_min_pd(x, y) returns y when x is NaN, so starting from +inf NaNs drop out.
        __m256d lo = _mm256_set1_pd(INFINITY), hi = _mm256_set1_pd(-INFINITY);
        for (int k = 0; k < 16; k += 4) {
            const __m256d x = _mm256_loadu_pd(v + k);
            lo = _mm256_min_pd(x, lo);
            hi = _mm256_max_pd(x, hi);
        }
        out.lo[a] = static_cast<float>(hmin(lo));
        out.hi[a] = static_cast<float>(hmax(hi));
    }
}

// A whole row's blocks at once, block by block.
__attribute__((target("avx2"))) void row_bounds_avx2(const DVec3Array& position, std::size_t begin,
                                                      std::size_t count, Box* out) {
    const double* axes[3] = {position.x.data() + begin, position.y.data() + begin, position.z.data() + begin};
    std::size_t c = 0;
    for (; c + 16 <= count; c += 16, ++out) block_bounds_avx2(axes, c, *out);
    if (c < count) *out = particle_bounds(position, begin + c, begin + count);
}

// A block's lowest point: a box open on every other side, or the empty box when no y is a number (as
// particle_bounds leaves a block of NaN particles).
Box lowest_box(double lowest) {
    if (!(lowest < INFINITY)) return Box{};
    return Box{glm::vec3(-INFINITY, static_cast<float>(lowest), -INFINITY), glm::vec3(INFINITY)};
}

double lowest_generic(const double* y, std::size_t n) {
    double lo = INFINITY, hi = -INFINITY;
    bounds_generic(y, n, lo, hi);  // NaN left out
    return lo;
}

// A row's blocks' lowest points: four vectors of the y axis per full block, then a shuffle reduction.
__attribute__((target("avx2"))) void row_lowest_avx2(const double* y, std::size_t count, Box* out) {
    std::size_t c = 0;
    for (; c + 16 <= count; c += 16, ++out) {
        const __m256d inf = _mm256_set1_pd(INFINITY);  // _mm256_min_pd(x, lo) is lo when x is NaN
        __m256d lo0 = _mm256_min_pd(_mm256_loadu_pd(y + c), inf);
        __m256d lo1 = _mm256_min_pd(_mm256_loadu_pd(y + c + 4), inf);
        lo0 = _mm256_min_pd(_mm256_loadu_pd(y + c + 8), lo0);
        lo1 = _mm256_min_pd(_mm256_loadu_pd(y + c + 12), lo1);
        *out = lowest_box(hmin(_mm256_min_pd(lo0, lo1)));  // no NaN left in either
    }
    if (c < count) *out = lowest_box(lowest_generic(y + c, count - c));
}

#define CLOTHSIM_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma")))
// maskz with all lanes throughout: the unmasked forms trip GCC 12's -Wuninitialized in its header.
template <bool Max>
[[gnu::always_inline]] CLOTHSIM_AVX512 inline __m512d bound(__m512d a, __m512d b) {
    return Max ? _mm512_maskz_max_pd(0xFF, a, b) : _mm512_maskz_min_pd(0xFF, a, b);
}
// Eight blocks' bounds of one axis folded together: v[j] holds block j's bounds lane by lane (no NaN), and
// three rounds of shuffles and minima (maxima) leave block k in lane 2k and block k + 4 in lane 2k + 1
// (the transpose-and-reduce of eight vectors: 21 instructions, where one vector's own reduction takes 6).
template <bool Max>
[[gnu::always_inline]] CLOTHSIM_AVX512 inline __m512d fold8(const __m512d v[8]) {
    __m512d s[4], u[2];
    for (int p = 0; p < 4; ++p) {  // 128-bit chunks 0-1: block 2p's halves folded; chunks 2-3: block 2p + 1's
        s[p] = bound<Max>(_mm512_maskz_shuffle_f64x2(0xFF, v[2 * p], v[2 * p + 1], _MM_SHUFFLE(1, 0, 1, 0)),
                          _mm512_maskz_shuffle_f64x2(0xFF, v[2 * p], v[2 * p + 1], _MM_SHUFFLE(3, 2, 3, 2)));
    }
    for (int p = 0; p < 2; ++p) {  // chunk k: block 4p + k
        u[p] = bound<Max>(_mm512_maskz_shuffle_f64x2(0xFF, s[2 * p], s[2 * p + 1], _MM_SHUFFLE(2, 0, 2, 0)),
                          _mm512_maskz_shuffle_f64x2(0xFF, s[2 * p], s[2 * p + 1], _MM_SHUFFLE(3, 1, 3, 1)));
    }
    return bound<Max>(_mm512_maskz_unpacklo_pd(0xFF, u[0], u[1]), _mm512_maskz_unpackhi_pd(0xFF, u[0], u[1]));
}

// Where fold8 leaves block j of eight (lane 2k: block k, lane 2k + 1: block k + 4).
constexpr int folded_lane(int j) { return j < 4 ? 2 * j : 2 * (j - 4) + 1; }

// The permutes that write eight boxes (48 floats: lo.x, lo.y, lo.z, hi.x, hi.y, hi.z each) as three vectors of
// sixteen from the folded bounds paired as [lo.x | lo.y], [lo.z | hi.x] and [hi.y | hi.z]: output float f is
// box f / 6's bound f % 6, taken from pair (f % 6) / 2 at 8 ((f % 6) % 2) + folded_lane(f / 6).
struct BoxPermutes {
    // For each output vector: indices into the first two pairs (vpermt2ps: 0-15 the first, 16-31 the second),
    // indices into the third, and the mask of the floats that come from the third.
    std::array<std::array<int, 16>, 3> first_two{}, third{};
    std::array<unsigned, 3> from_third{};
};
constexpr BoxPermutes box_permutes() {
    BoxPermutes p;
    for (int k = 0; k < 3; ++k) {
        for (int t = 0; t < 16; ++t) {
            const int f = 16 * k + t, box = f / 6, bound_of = f % 6;
            const int index = 8 * (bound_of % 2) + folded_lane(box);
            if (bound_of / 2 == 2) {
                p.third[k][t] = index;
                p.from_third[k] |= 1u << t;
            } else {
                p.first_two[k][t] = 16 * (bound_of / 2) + index;
            }
        }
    }
    return p;
}
constexpr BoxPermutes kBoxPermutes = box_permutes();
static_assert(sizeof(Box) == 6 * sizeof(float), "eight boxes are written as 48 consecutive floats");

// Eight full blocks' boxes from column c: per axis sixteen loads, each block's two vectors bounded lane by
// lane from +-inf (_mm512_min_pd(x, y) returns y when x is NaN, so NaN coordinates drop out and the fold sees
// none), folded (fold8), rounded to float and written with three permutes per vector of boxes.
CLOTHSIM_AVX512 void eight_blocks_avx512(const double* const axes[3], std::size_t c, Box* out) {
    __m256 bounds[6];  // lo.x, lo.y, lo.z, hi.x, hi.y, hi.z of the eight blocks, in folded_lane order
    for (int a = 0; a < 3; ++a) {
        __m512d lo[8], hi[8];
        for (int j = 0; j < 8; ++j) {
            const double* v = axes[a] + c + 16 * j;
            const __m512d x0 = _mm512_loadu_pd(v), x1 = _mm512_loadu_pd(v + 8);
            lo[j] = bound<false>(x1, bound<false>(x0, _mm512_set1_pd(INFINITY)));
            hi[j] = bound<true>(x1, bound<true>(x0, _mm512_set1_pd(-INFINITY)));
        }
        bounds[a] = _mm512_maskz_cvtpd_ps(0xFF, fold8<false>(lo));
        bounds[3 + a] = _mm512_maskz_cvtpd_ps(0xFF, fold8<true>(hi));
    }
    const __m512 pairs[3] = {
        _mm512_insertf32x8(_mm512_castps256_ps512(bounds[0]), bounds[1], 1),
        _mm512_insertf32x8(_mm512_castps256_ps512(bounds[2]), bounds[3], 1),
        _mm512_insertf32x8(_mm512_castps256_ps512(bounds[4]), bounds[5], 1),
    };
    auto* floats = reinterpret_cast<float*>(out);
    for (int k = 0; k < 3; ++k) {
        const __m512i first_two = _mm512_loadu_si512(kBoxPermutes.first_two[k].data());
        const __m512i third = _mm512_loadu_si512(kBoxPermutes.third[k].data());
        const __m512 v = _mm512_mask_permutexvar_ps(_mm512_permutex2var_ps(pairs[0], first_two, pairs[1]),
                                                    static_cast<__mmask16>(kBoxPermutes.from_third[k]), third,
                                                    pairs[2]);
        _mm512_storeu_ps(floats + 16 * k, v);
    }
}

// The row's blocks eight at a time, the rest of its full blocks one at a time, then the partial one.
CLOTHSIM_AVX512 void row_bounds_avx512(const DVec3Array& position, std::size_t begin, std::size_t count, Box* out) {
    const double* axes[3] = {position.x.data() + begin, position.y.data() + begin, position.z.data() + begin};
    std::size_t c = 0;
    for (; c + 128 <= count; c += 128, out += 8) eight_blocks_avx512(axes, c, out);
    for (; c + 16 <= count; c += 16, ++out) block_bounds_avx2(axes, c, *out);
    if (c < count) *out = particle_bounds(position, begin + c, begin + count);
}
#undef CLOTHSIM_AVX512

const bool kAvx2 = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
}();

}  // namespace

Box particle_bounds(const DVec3Array& position, std::size_t begin, std::size_t end) {
    Box box;
    if (end <= begin) return box;
    const std::size_t n = end - begin;
    const double* axes[3] = {position.x.data() + begin, position.y.data() + begin, position.z.data() + begin};
    for (int a = 0; a < 3; ++a) {
        double lo = INFINITY, hi = -INFINITY;
        (kAvx2 ? bounds_avx2 : bounds_generic)(axes[a], n, lo, hi);
        box.lo[a] = static_cast<float>(lo);
        box.hi[a] = static_cast<float>(hi);
    }
    return box;
}

void include_motion(const DVec3Array& motion, std::size_t begin, std::size_t end, MotionBounds& bounds) {
    if (end <= begin) return;
    const std::size_t n = end - begin;
    const double* axes[3] = {motion.x.data() + begin, motion.y.data() + begin, motion.z.data() + begin};
    for (int a = 0; a < 3; ++a) {
        double lo = bounds.empty ? INFINITY : bounds.lo[a], hi = bounds.empty ? -INFINITY : bounds.hi[a];
        (kAvx2 ? bounds_avx2 : bounds_generic)(axes[a], n, lo, hi);
        bounds.lo[a] = lo;
        bounds.hi[a] = hi;
    }
    bounds.empty = false;
}

// Chosen as the fast solver chooses its kernels (FastSolver::kernel), so the tests run each one this CPU has.
// A minimum and a maximum round nothing: every kernel gives particle_bounds' boxes (up to the sign of a zero).
void row_block_bounds(const DVec3Array& position, std::size_t begin, std::size_t count, Box* out, BlockBounds bounds) {
    static_assert(kBlockParticles == 16, "the row kernels bound 16 particles per block");
    if (bounds == BlockBounds::Lowest) {
        const double* y = position.y.data() + begin;
        switch (FastSolver::kernel()) {
            case FastKernel::Avx512:  // four loads and a reduction per block: 512-bit vectors would save two loads
            case FastKernel::Avx2: row_lowest_avx2(y, count, out); return;
            case FastKernel::Generic: break;
        }
        for (std::size_t c = 0; c < count; c += kBlockParticles, ++out) {
            *out = lowest_box(lowest_generic(y + c, std::min(kBlockParticles, count - c)));
        }
        return;
    }
    switch (FastSolver::kernel()) {
        case FastKernel::Avx512: row_bounds_avx512(position, begin, count, out); return;
        case FastKernel::Avx2: row_bounds_avx2(position, begin, count, out); return;
        case FastKernel::Generic: break;
    }
    for (std::size_t c = 0; c < count; c += kBlockParticles, ++out) {
        *out = particle_bounds(position, begin + c, begin + std::min(c + kBlockParticles, count));
    }
}

std::vector<std::size_t> block_starts(std::size_t particles, int rows, int cols) {
    std::vector<std::size_t> start;
    if (cols > 0 && rows > 0 && static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols) == particles) {
        for (int r = 0; r < rows; ++r) {
            for (std::size_t c = 0; c < static_cast<std::size_t>(cols); c += kBlockParticles) {
                start.push_back(static_cast<std::size_t>(r) * cols + c);
            }
        }
    } else {
        for (std::size_t i = 0; i < particles; i += kBlockParticles) start.push_back(i);
    }
    start.push_back(particles);
    return start;
}

Box union_of(const Box* boxes, std::size_t n) {
    static_assert(sizeof(Box) == 6 * sizeof(float), "a Box is lo then hi, three floats each");
    Box all;
    if (n == 0) return all;
    // Four floats from each bound (the fourth lane, the next float in memory, is ignored); the last box alone,
    // so no load reads past the array. MINPS(v, lo) returns lo when either is NaN: glm::min(lo, v)'s
    // (v < lo ? v : lo), so no accumulator ever holds a NaN. Four accumulators each, so the loop waits on
    // MINPS's latency once per four boxes, not once per box (the union runs every substep, over a
    // thousand boxes at 128 x 128); min and max are exact, so the order does not change the result.
    __m128 lo[4], hi[4];
    for (int a = 0; a < 4; ++a) lo[a] = _mm_set1_ps(INFINITY), hi[a] = _mm_set1_ps(-INFINITY);
    std::size_t k = 0;
    for (; k + 4 < n; k += 4) {
        for (int a = 0; a < 4; ++a) {
            lo[a] = _mm_min_ps(_mm_loadu_ps(&boxes[k + a].lo.x), lo[a]);
            hi[a] = _mm_max_ps(_mm_loadu_ps(&boxes[k + a].hi.x), hi[a]);
        }
    }
    for (; k + 1 < n; ++k) {
        lo[0] = _mm_min_ps(_mm_loadu_ps(&boxes[k].lo.x), lo[0]);
        hi[0] = _mm_max_ps(_mm_loadu_ps(&boxes[k].hi.x), hi[0]);
    }
    for (int a = 1; a < 4; ++a) lo[0] = _mm_min_ps(lo[a], lo[0]), hi[0] = _mm_max_ps(hi[a], hi[0]);
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo[0]);
    _mm_store_ps(h, hi[0]);
    all.lo = glm::min(glm::vec3(l[0], l[1], l[2]), boxes[n - 1].lo);
    all.hi = glm::max(glm::vec3(h[0], h[1], h[2]), boxes[n - 1].hi);
    return all;
}

}  // namespace clothsim
