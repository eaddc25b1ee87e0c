// Floors of the AVX-512 spring kernel: what each part of it costs per spring, L1-resident rows.
// Not part of the build (docs/PERFORMANCE.md, session 18): g++ -O2 -std=c++20 -I include \
//     bench/results/kernel-parts-2026-12-03-s18/avx512_parts.cpp -o /tmp/avx512_parts && /tmp/avx512_parts
#include <immintrin.h>
#include <chrono>
#include <cstdio>
#include <vector>
#include <algorithm>
#include <cmath>
#include "clothsim/aligned_allocator.hpp"
using namespace clothsim;
#define T __attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma")))
#define AI [[gnu::always_inline]] inline
T AI __m256 diff8(const double* p, int i, int o) {
    return _mm512_maskz_cvtpd_ps(0xFF, _mm512_sub_pd(_mm512_loadu_pd(p + i + o), _mm512_loadu_pd(p + i)));
}
T AI __m512 diff16(const double* p, int i, int o) {
    return _mm512_insertf32x8(_mm512_castps256_ps512(diff8(p, i, o)), diff8(p, i + 8, o), 1);
}
T AI __m512 diff16f(const float* p, int i, int o) { return _mm512_sub_ps(_mm512_loadu_ps(p + i + o), _mm512_loadu_ps(p + i)); }
T AI __m512 diff16hl(const float* h, const float* l, int i, int o) {
    return _mm512_add_ps(_mm512_sub_ps(_mm512_loadu_ps(h + i + o), _mm512_loadu_ps(h + i)),
                         _mm512_sub_ps(_mm512_loadu_ps(l + i + o), _mm512_loadu_ps(l + i)));
}
template <int V> T AI void forces(__m512 dx, __m512 dy, __m512 dz, const float* rest, float k, float* fx, float* fy, float* fz) {
    const __m512 vk = _mm512_set1_ps(k), tiny = _mm512_set1_ps(1e-12f), zero = _mm512_setzero_ps();
    __m512 s;
    const __m512 l0 = _mm512_loadu_ps(rest);
    if (V == 0) {  // exact
        const __m512 r2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)), _mm512_mul_ps(dz, dz));
        const __m512 length = _mm512_maskz_sqrt_ps(0xFFFF, r2);
        const __m512 st = _mm512_div_ps(_mm512_mul_ps(vk, _mm512_sub_ps(length, l0)), length);
        const __m512 apart = _mm512_maskz_mov_ps(_mm512_cmp_ps_mask(length, tiny, _CMP_GT_OQ), st);
        s = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(l0, zero, _CMP_EQ_OQ), apart, vk);
    } else if (V == 1) {  // rsqrt14 + Newton, FMA
        const __m512 r2 = _mm512_fmadd_ps(dz, dz, _mm512_fmadd_ps(dy, dy, _mm512_mul_ps(dx, dx)));
        const __m512 y0 = _mm512_rsqrt14_ps(r2);
        const __m512 hr = _mm512_mul_ps(_mm512_set1_ps(0.5f), r2);
        const __m512 inv = _mm512_mul_ps(y0, _mm512_fnmadd_ps(_mm512_mul_ps(hr, y0), y0, _mm512_set1_ps(1.5f)));
        const __m512 st = _mm512_fnmadd_ps(_mm512_mul_ps(vk, l0), inv, vk);
        s = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(l0, zero, _CMP_EQ_OQ), st, vk);
    } else {  // no sqrt or divide: s = k (r2 - l0)
        const __m512 r2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)), _mm512_mul_ps(dz, dz));
        s = _mm512_mul_ps(vk, _mm512_sub_ps(r2, l0));
    }
    _mm512_storeu_ps(fx, _mm512_mul_ps(s, dx));
    _mm512_storeu_ps(fy, _mm512_mul_ps(s, dy));
    _mm512_storeu_ps(fz, _mm512_mul_ps(s, dz));
}
struct Data {
    int n; AlignedVector<double> x, y, z; AlignedVector<float> xf, yf, zf, xl, yl, zl, rest, fx, fy, fz;
};
template <int V> T __attribute__((noinline)) void run_d(Data& d, int o) {
    for (int i = 0; i + 16 <= d.n; i += 16)
        forces<V>(diff16(d.x.data(), i, o), diff16(d.y.data(), i, o), diff16(d.z.data(), i, o), d.rest.data() + i, 1000.f,
                  d.fx.data() + i, d.fy.data() + i, d.fz.data() + i);
}
template <int V> T __attribute__((noinline)) void run_f(Data& d, int o) {
    for (int i = 0; i + 16 <= d.n; i += 16)
        forces<V>(diff16f(d.xf.data(), i, o), diff16f(d.yf.data(), i, o), diff16f(d.zf.data(), i, o), d.rest.data() + i, 1000.f,
                  d.fx.data() + i, d.fy.data() + i, d.fz.data() + i);
}
template <int V> T __attribute__((noinline)) void run_hl(Data& d, int o) {
    for (int i = 0; i + 16 <= d.n; i += 16)
        forces<V>(diff16hl(d.xf.data(), d.xl.data(), i, o), diff16hl(d.yf.data(), d.yl.data(), i, o), diff16hl(d.zf.data(), d.zl.data(), i, o),
                  d.rest.data() + i, 1000.f, d.fx.data() + i, d.fy.data() + i, d.fz.data() + i);
}
T __attribute__((noinline)) void run_mem(Data& d, int o) {  // the loads and stores only
    for (int i = 0; i + 16 <= d.n; i += 16) {
        __m512d a = _mm512_add_pd(_mm512_loadu_pd(&d.x[i + o]), _mm512_loadu_pd(&d.x[i]));
        __m512d b = _mm512_add_pd(_mm512_loadu_pd(&d.x[i + o + 8]), _mm512_loadu_pd(&d.x[i + 8]));
        __m512d c = _mm512_add_pd(_mm512_loadu_pd(&d.y[i + o]), _mm512_loadu_pd(&d.y[i]));
        __m512d e = _mm512_add_pd(_mm512_loadu_pd(&d.y[i + o + 8]), _mm512_loadu_pd(&d.y[i + 8]));
        __m512d f = _mm512_add_pd(_mm512_loadu_pd(&d.z[i + o]), _mm512_loadu_pd(&d.z[i]));
        __m512d g = _mm512_add_pd(_mm512_loadu_pd(&d.z[i + o + 8]), _mm512_loadu_pd(&d.z[i + 8]));
        __m512 r = _mm512_loadu_ps(&d.rest[i]);
        _mm512_storeu_ps(&d.fx[i], _mm512_add_ps(r, _mm512_castpd_ps(_mm512_add_pd(a, b))));
        _mm512_storeu_ps(&d.fy[i], _mm512_castpd_ps(_mm512_add_pd(c, e)));
        _mm512_storeu_ps(&d.fz[i], _mm512_castpd_ps(_mm512_add_pd(f, g)));
    }
}
T AI __m256 diff8a(const double* p, int i) {  // p[i+1]-p[i] with aligned loads and valignq
    const __m512d a = _mm512_load_pd(p + i), b = _mm512_load_pd(p + i + 8);
    return _mm512_maskz_cvtpd_ps(0xFF, _mm512_sub_pd(_mm512_castsi512_pd(_mm512_alignr_epi64(_mm512_castpd_si512(b), _mm512_castpd_si512(a), 1)), a));
}
T AI __m512 diff16a(const double* p, int i) {
    const __m512d a = _mm512_load_pd(p + i), b = _mm512_load_pd(p + i + 8), c = _mm512_load_pd(p + i + 16);
    const __m256 lo = _mm512_maskz_cvtpd_ps(0xFF, _mm512_sub_pd(_mm512_castsi512_pd(_mm512_alignr_epi64(_mm512_castpd_si512(b), _mm512_castpd_si512(a), 1)), a));
    const __m256 hi = _mm512_maskz_cvtpd_ps(0xFF, _mm512_sub_pd(_mm512_castsi512_pd(_mm512_alignr_epi64(_mm512_castpd_si512(c), _mm512_castpd_si512(b), 1)), b));
    return _mm512_insertf32x8(_mm512_castps256_ps512(lo), hi, 1);
}
template <int V> T __attribute__((noinline)) void run_a(Data& d, int) {
    for (int i = 0; i + 16 <= d.n; i += 16)
        forces<V>(diff16a(d.x.data(), i), diff16a(d.y.data(), i), diff16a(d.z.data(), i), d.rest.data() + i, 1000.f,
                  d.fx.data() + i, d.fy.data() + i, d.fz.data() + i);
}
template <class F> double ns_per_spring(F f, Data& d, int off = 1) {
    std::vector<double> t;
    for (int rep = 0; rep < 15; ++rep) {
        auto a = std::chrono::steady_clock::now();
        for (int k = 0; k < 2000; ++k) f(d, off);
        auto b = std::chrono::steady_clock::now();
        t.push_back(std::chrono::duration<double, std::nano>(b - a).count() / (2000.0 * (d.n / 16 * 16)));
    }
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}
int main() {
    Data d; d.n = 1024; int m = d.n + 32;
    for (auto* v : {&d.x, &d.y, &d.z}) v->resize(m);  // std::vector<double>: 16-byte aligned only
    for (auto* v : {&d.xf, &d.yf, &d.zf, &d.xl, &d.yl, &d.zl, &d.rest, &d.fx, &d.fy, &d.fz}) v->resize(m);
    for (int i = 0; i < m; ++i) {
        d.x[i] = 0.01 * i + 1e-4 * std::sin(i); d.y[i] = 1.5 + 1e-3 * std::cos(i); d.z[i] = 0.3 * std::sin(0.01 * i);
        d.xf[i] = d.x[i]; d.yf[i] = d.y[i]; d.zf[i] = d.z[i];
        d.xl[i] = d.x[i] - d.xf[i]; d.yl[i] = d.y[i] - d.yf[i]; d.zl[i] = d.z[i] - d.zf[i];
        d.rest[i] = 0.0099f;
    }
    for (int round = 0; round < 3; ++round)
    std::printf("offset 1: %.3f | offset 8 (no split): %.3f | offset 1 by valign: %.3f | offset 128: %.3f | offset 129: %.3f\n", ns_per_spring(run_d<0>, d, 1), ns_per_spring(run_d<0>, d, 8), ns_per_spring(run_a<0>, d, 1), ns_per_spring(run_d<0>, d, 128), ns_per_spring(run_d<0>, d, 129));
    for (int round = 0; round < 1; ++round)
    std::printf("exact %.3f | rsqrt+fma %.3f | no sqrt/div %.3f | float diffs exact %.3f | hi+lo diffs exact %.3f | memory only %.3f ns/spring\n",
                ns_per_spring(run_d<0>, d), ns_per_spring(run_d<1>, d), ns_per_spring(run_d<2>, d),
                ns_per_spring(run_f<0>, d), ns_per_spring(run_hl<0>, d), ns_per_spring(run_mem, d));
}
