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

const bool kAvx2 = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
}();

// Room for rounding: a relative 1e-5 of the magnitudes involved (float's epsilon is 6e-8).
float margin(float scale) { return 1e-5f * (1.0f + scale); }

}  // namespace

Box particle_bounds(const Vec3Array& position, std::size_t begin, std::size_t end) {
    Box box;
    if (end <= begin) return box;
    const std::size_t n = end - begin;
    const float* axes[3] = {position.x.data() + begin, position.y.data() + begin, position.z.data() + begin};
    for (int a = 0; a < 3; ++a) (kAvx2 ? bounds_avx2 : bounds_generic)(axes[a], n, box.lo[a], box.hi[a]);
    return box;
}

bool may_touch(const SphereCollider& sphere, float thickness, const Box& box) {
    if (box.empty()) return false;
    const glm::vec3 nearest = glm::clamp(sphere.center, box.lo, box.hi);
    const glm::vec3 d = sphere.center - nearest;
    const float reach = sphere.radius + thickness;
    const float grown = reach + margin(reach + glm::length(sphere.center) + glm::length(nearest));
    return glm::dot(d, d) < grown * grown;
}

bool may_touch(const CubeCollider& cube, float thickness, const Box& box) {
    if (box.empty()) return false;
    const glm::vec3 half = 0.5f * cube.size + thickness;
    const glm::vec3 grow(margin(glm::length(cube.center) + glm::length(half) + glm::length(box.hi - box.lo)));
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
