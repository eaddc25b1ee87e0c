// The AVX2 spring kernel's parts per spring, L1-resident rows: double differences (today), float differences
// (the float-state build), hi + lo float differences (positions as two floats) and int32 differences
// (positions in fixed point, 2^-30 m, relative to an origin).
// Not part of the build (docs/PERFORMANCE.md, session 18): g++ -O2 -std=c++20 -I include \
//     bench/results/kernel-parts-2026-12-03-s18/avx2_parts.cpp -o /tmp/avx2_parts && /tmp/avx2_parts
#include <immintrin.h>
#include <chrono>
#include <cstdio>
#include <vector>
#include <algorithm>
#include <cmath>
#include "clothsim/aligned_allocator.hpp"
using namespace clothsim;
#define T __attribute__((target("avx2,fma")))
#define AI [[gnu::always_inline]] inline
T AI __m256 diffd(const double* p, int i, int o) {
    const __m128 lo = _mm256_cvtpd_ps(_mm256_sub_pd(_mm256_loadu_pd(p + i + o), _mm256_loadu_pd(p + i)));
    const __m128 hi = _mm256_cvtpd_ps(_mm256_sub_pd(_mm256_loadu_pd(p + i + o + 4), _mm256_loadu_pd(p + i + 4)));
    return _mm256_insertf128_ps(_mm256_castps128_ps256(lo), hi, 1);
}
T AI __m256 difff(const float* p, int i, int o) { return _mm256_sub_ps(_mm256_loadu_ps(p + i + o), _mm256_loadu_ps(p + i)); }
T AI __m256 diffhl(const float* h, const float* l, int i, int o) {
    return _mm256_add_ps(_mm256_sub_ps(_mm256_loadu_ps(h + i + o), _mm256_loadu_ps(h + i)),
                         _mm256_sub_ps(_mm256_loadu_ps(l + i + o), _mm256_loadu_ps(l + i)));
}
T AI void forces8(__m256 dx, __m256 dy, __m256 dz, const float* rest, float k, float* fx, float* fy, float* fz) {
    const __m256 vk = _mm256_set1_ps(k), tiny = _mm256_set1_ps(1e-12f), zero = _mm256_setzero_ps();
    const __m256 r2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
    const __m256 length = _mm256_sqrt_ps(r2);
    const __m256 l0 = _mm256_loadu_ps(rest);
    const __m256 stretched = _mm256_div_ps(_mm256_mul_ps(vk, _mm256_sub_ps(length, l0)), length);
    const __m256 apart = _mm256_blendv_ps(zero, stretched, _mm256_cmp_ps(length, tiny, _CMP_GT_OQ));
    const __m256 s = _mm256_blendv_ps(apart, vk, _mm256_cmp_ps(l0, zero, _CMP_EQ_OQ));
    _mm256_storeu_ps(fx, _mm256_mul_ps(s, dx));
    _mm256_storeu_ps(fy, _mm256_mul_ps(s, dy));
    _mm256_storeu_ps(fz, _mm256_mul_ps(s, dz));
}
struct Data { int n; AlignedVector<double> x, y, z; AlignedVector<float> xf, yf, zf, xl, yl, zl, rest, fx, fy, fz; AlignedVector<int> xi, yi, zi; };
T AI __m256 diffi(const int* p, int i, int o, __m256 scale) {  // fixed point: (q_b - q_a) exactly in int32, then one rounding
    return _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_loadu_si256((const __m256i*)(p + i + o)), _mm256_loadu_si256((const __m256i*)(p + i)))), scale);
}
T __attribute__((noinline)) void run_d(Data& d, int o) {
    for (int i = 0; i + 8 <= d.n; i += 8)
        forces8(diffd(d.x.data(), i, o), diffd(d.y.data(), i, o), diffd(d.z.data(), i, o), d.rest.data() + i, 1000.f, d.fx.data() + i, d.fy.data() + i, d.fz.data() + i);
}
T __attribute__((noinline)) void run_f(Data& d, int o) {
    for (int i = 0; i + 8 <= d.n; i += 8)
        forces8(difff(d.xf.data(), i, o), difff(d.yf.data(), i, o), difff(d.zf.data(), i, o), d.rest.data() + i, 1000.f, d.fx.data() + i, d.fy.data() + i, d.fz.data() + i);
}
T __attribute__((noinline)) void run_hl(Data& d, int o) {
    for (int i = 0; i + 8 <= d.n; i += 8)
        forces8(diffhl(d.xf.data(), d.xl.data(), i, o), diffhl(d.yf.data(), d.yl.data(), i, o), diffhl(d.zf.data(), d.zl.data(), i, o), d.rest.data() + i, 1000.f, d.fx.data() + i, d.fy.data() + i, d.fz.data() + i);
}
T __attribute__((noinline)) void run_i(Data& d, int o) {
    const __m256 sc = _mm256_set1_ps(std::ldexp(1.0f, -30));
    for (int i = 0; i + 8 <= d.n; i += 8)
        forces8(diffi(d.xi.data(), i, o, sc), diffi(d.yi.data(), i, o, sc), diffi(d.zi.data(), i, o, sc), d.rest.data() + i, 1000.f, d.fx.data() + i, d.fy.data() + i, d.fz.data() + i);
}
template <class F> double ns_per_spring(F f, Data& d, int off = 1) {
    std::vector<double> t;
    for (int rep = 0; rep < 21; ++rep) {
        auto a = std::chrono::steady_clock::now();
        for (int k = 0; k < 2000; ++k) f(d, off);
        auto b = std::chrono::steady_clock::now();
        t.push_back(std::chrono::duration<double, std::nano>(b - a).count() / (2000.0 * (d.n / 8 * 8)));
    }
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}
int main() {
    Data d; d.n = 1024; int m = d.n + 32;
    for (auto* v : {&d.x, &d.y, &d.z}) v->resize(m);
    for (auto* v : {&d.xi, &d.yi, &d.zi}) v->resize(m);
    for (auto* v : {&d.xf, &d.yf, &d.zf, &d.xl, &d.yl, &d.zl, &d.rest, &d.fx, &d.fy, &d.fz}) v->resize(m);
    for (int i = 0; i < m; ++i) {
        d.x[i] = 0.01 * i + 1e-4 * std::sin(i); d.y[i] = 1.5 + 1e-3 * std::cos(i); d.z[i] = 0.3 * std::sin(0.01 * i);
        d.xf[i] = d.x[i]; d.yf[i] = d.y[i]; d.zf[i] = d.z[i];
        d.xl[i] = d.x[i] - d.xf[i]; d.yl[i] = d.y[i] - d.yf[i]; d.zl[i] = d.z[i] - d.zf[i];
        d.rest[i] = 0.0099f;
        d.xi[i] = int(std::ldexp(d.x[i] - 5.0, 30)); d.yi[i] = int(std::ldexp(d.y[i] - 1.5, 30)); d.zi[i] = int(std::ldexp(d.z[i], 30));
    }
    for (int round = 0; round < 5; ++round) {
        const double a = ns_per_spring(run_d, d), b = ns_per_spring(run_f, d), c = ns_per_spring(run_hl, d), e = ns_per_spring(run_i, d);
        std::printf("AVX2: double diffs %.3f | float diffs %.3f (%.2fx) | hi+lo diffs %.3f (%.2fx) | int32 fixed-point diffs %.3f (%.2fx) ns/spring\n", a, b, a / b, c, a / c, e, a / e);
    }
}
