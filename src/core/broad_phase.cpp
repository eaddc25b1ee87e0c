#include "clothsim/broad_phase.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <immintrin.h>

#include <algorithm>

namespace clothsim {
namespace {

// GCC does not vectorise a float min/max reduction without -ffinite-math-only, so the AVX2 loop is written
// out. _mm256_min_ps(x, lo) returns lo when x is NaN, which leaves NaN coordinates out, as the scalar loop does.
__attribute__((target("avx2"))) void bounds_avx2(const float* v, std::size_t n, float& lo, float& hi) {
    __m256 l = _mm256_set1_ps(INFINITY), h = _mm256_set1_ps(-INFINITY);
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        const __m256 x = _mm256_loadu_ps(v + i);
        l = _mm256_min_ps(x, l);
        h = _mm256_max_ps(x, h);
    }
    alignas(32) float ls[8], hs[8];
    _mm256_store_ps(ls, l);
    _mm256_store_ps(hs, h);
    for (int k = 0; k < 8; ++k) {
        lo = std::min(lo, ls[k]);
        hi = std::max(hi, hs[k]);
    }
    for (; i < n; ++i) {
        lo = v[i] < lo ? v[i] : lo;
        hi = hi < v[i] ? v[i] : hi;
    }
}

void bounds_generic(const float* v, std::size_t n, float& lo, float& hi) {
    for (std::size_t i = 0; i < n; ++i) {
        lo = v[i] < lo ? v[i] : lo;
        hi = hi < v[i] ? v[i] : hi;
    }
}

__attribute__((target("avx2"))) inline float hmin(__m256 v) {
    __m128 m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
    m = _mm_min_ps(m, _mm_movehl_ps(m, m));
    m = _mm_min_ss(m, _mm_shuffle_ps(m, m, 1));
    return _mm_cvtss_f32(m);
}
__attribute__((target("avx2"))) inline float hmax(__m256 v) {
    __m128 m = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
    m = _mm_max_ps(m, _mm_movehl_ps(m, m));
    m = _mm_max_ss(m, _mm_shuffle_ps(m, m, 1));
    return _mm_cvtss_f32(m);
}

// A whole row's blocks at once: full blocks of 16 are two vectors per axis and a shuffle reduction.
__attribute__((target("avx2"))) void row_bounds_avx2(const Vec3Array& position, std::size_t begin, std::size_t count,
                                                      Box* out) {
    const float* axes[3] = {position.x.data() + begin, position.y.data() + begin, position.z.data() + begin};
    std::size_t c = 0;
    for (; c + 16 <= count; c += 16, ++out) {
        for (int a = 0; a < 3; ++a) {
            const __m256 v0 = _mm256_loadu_ps(axes[a] + c), v1 = _mm256_loadu_ps(axes[a] + c + 8);
            // min(v0, min(v1, +inf)) style: _mm256_min_ps(x, y) returns y when x is NaN, so NaNs drop out.
            const __m256 lo = _mm256_min_ps(v0, _mm256_min_ps(v1, _mm256_set1_ps(INFINITY)));
            const __m256 hi = _mm256_max_ps(v0, _mm256_max_ps(v1, _mm256_set1_ps(-INFINITY)));
            out->lo[a] = hmin(lo);
            out->hi[a] = hmax(hi);
        }
    }
    if (c < count) *out = particle_bounds(position, begin + c, begin + count);
}

const bool kAvx2 = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
}();

// Room for rounding: a relative 1e-5 of the magnitudes involved (float's epsilon is 6e-8).
float margin(float scale) { return 1e-5f * (1.0f + scale); }
float largest(glm::vec3 v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

}  // namespace

Box particle_bounds(const Vec3Array& position, std::size_t begin, std::size_t end) {
    Box box;
    if (end <= begin) return box;
    const std::size_t n = end - begin;
    const float* axes[3] = {position.x.data() + begin, position.y.data() + begin, position.z.data() + begin};
    for (int a = 0; a < 3; ++a) (kAvx2 ? bounds_avx2 : bounds_generic)(axes[a], n, box.lo[a], box.hi[a]);
    return box;
}

void row_block_bounds(const Vec3Array& position, std::size_t begin, std::size_t count, Box* out) {
    static_assert(kBlockParticles == 16, "row_bounds_avx2 reduces two vectors per block");
    if (kAvx2) {
        row_bounds_avx2(position, begin, count, out);
        return;
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

bool may_touch(const SphereCollider& sphere, float thickness, const Box& box) {
    if (box.empty()) return false;
    const glm::vec3 nearest = glm::clamp(sphere.center, box.lo, box.hi);
    const glm::vec3 d = sphere.center - nearest;
    const float reach = sphere.radius + thickness;
    // |v| <= 2 x largest component for a 3-vector: a cheap stand-in for the lengths in the rounding margin.
    const float grown = reach + margin(reach + 2.0f * (largest(sphere.center) + largest(nearest)));
    return glm::dot(d, d) < grown * grown;
}

bool may_touch(const CubeCollider& cube, float thickness, const Box& box) {
    if (box.empty()) return false;
    const glm::vec3 half = 0.5f * cube.size + thickness;
    const glm::vec3 grow(margin(2.0f * (largest(cube.center) + largest(half) + largest(box.lo) + largest(box.hi))));
    const glm::vec3 lo = cube.center - half - grow, hi = cube.center + half + grow;
    return box.lo.x < hi.x && box.hi.x > lo.x && box.lo.y < hi.y && box.hi.y > lo.y && box.lo.z < hi.z &&
           box.hi.z > lo.z;
}

bool may_touch(const GroundCollider& ground, float thickness, const Box& box) {
    if (box.empty()) return false;
    const float top = ground.height + thickness;
    return box.lo.y < top + margin(std::abs(top) + std::abs(box.lo.y));
}

}  // namespace clothsim
