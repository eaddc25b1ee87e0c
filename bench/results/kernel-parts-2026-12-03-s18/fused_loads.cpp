// One row's six spring directions (4 springs + 2 bends) on a 128-column grid, AVX-512, exact arithmetic:
// separate runs (today's kernel: each direction loads both ends) against one pass per 16 columns that loads
// each row's positions once per shift and reuses them across directions. Interior columns only.
// Not part of the build (docs/PERFORMANCE.md, session 18): g++ -O2 -std=c++20 -I include \
//     bench/results/kernel-parts-2026-12-03-s18/fused_loads.cpp -o /tmp/fused_loads && /tmp/fused_loads
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
constexpr int C = 128, R = 8, B = 8, E = C - 24;  // columns [B, E) of every row
T AI __m256 cvt(__m512d d) { return _mm512_maskz_cvtpd_ps(0xFF, d); }
T AI __m512 join(__m256 a, __m256 b) { return _mm512_insertf32x8(_mm512_castps256_ps512(a), b, 1); }
T AI __m512 diff16(const double* p, int i, int o) {
    return join(cvt(_mm512_sub_pd(_mm512_loadu_pd(p + i + o), _mm512_loadu_pd(p + i))),
                cvt(_mm512_sub_pd(_mm512_loadu_pd(p + i + o + 8), _mm512_loadu_pd(p + i + 8))));
}
T AI void forces(__m512 dx, __m512 dy, __m512 dz, const float* rest, float k, float* fx, float* fy, float* fz) {
    const __m512 vk = _mm512_set1_ps(k), tiny = _mm512_set1_ps(1e-12f), zero = _mm512_setzero_ps();
    const __m512 l0 = _mm512_loadu_ps(rest);
    const __m512 r2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)), _mm512_mul_ps(dz, dz));
    const __m512 length = _mm512_maskz_sqrt_ps(0xFFFF, r2);
    const __m512 st = _mm512_div_ps(_mm512_mul_ps(vk, _mm512_sub_ps(length, l0)), length);
    const __m512 apart = _mm512_maskz_mov_ps(_mm512_cmp_ps_mask(length, tiny, _CMP_GT_OQ), st);
    const __m512 s = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(l0, zero, _CMP_EQ_OQ), apart, vk);
    _mm512_storeu_ps(fx, _mm512_mul_ps(s, dx)); _mm512_storeu_ps(fy, _mm512_mul_ps(s, dy)); _mm512_storeu_ps(fz, _mm512_mul_ps(s, dz));
}
T AI __m256 second8(__m512d a, __m512d m, __m512d b) { return cvt(_mm512_add_pd(_mm512_sub_pd(a, m), _mm512_sub_pd(b, m))); }
T AI void bend16(const double* const p[3], int i, int o, float k, float* const f[3]) {
    for (int c = 0; c < 3; ++c) {
        const double* q = p[c] + i;
        __m512 e = join(second8(_mm512_loadu_pd(q), _mm512_loadu_pd(q + o), _mm512_loadu_pd(q + 2 * o)),
                        second8(_mm512_loadu_pd(q + 8), _mm512_loadu_pd(q + o + 8), _mm512_loadu_pd(q + 2 * o + 8)));
        _mm512_storeu_ps(f[c], _mm512_mul_ps(_mm512_set1_ps(k), e));
    }
}
struct Data { AlignedVector<double> x, y, z; AlignedVector<float> rest, out; };
constexpr int kOff[6] = {1, C, C + 1, C - 1, 1, C};  // springs: right, down, down-right, down-left; bends: right, down (half offsets)
T __attribute__((noinline)) void separate(Data& d, int r) {
    const double* p[3] = {d.x.data(), d.y.data(), d.z.data()};
    for (int dir = 0; dir < 6; ++dir) {
        float* f = d.out.data() + dir * 3 * C;
        for (int c = B; c + 16 <= E; c += 16) {
            const int i = r * C + c;
            float* const o[3] = {f + c, f + C + c, f + 2 * C + c};
            if (dir < 4) forces(diff16(p[0], i, kOff[dir]), diff16(p[1], i, kOff[dir]), diff16(p[2], i, kOff[dir]), d.rest.data() + c, 1000.f, o[0], o[1], o[2]);
            else bend16(p, i, kOff[dir], 5.f, o);
        }
    }
}
// Per component and half: the row's own positions at c, c+1, c+2; the next row's at c-1, c, c+1; two rows down at c.
struct Loads { __m512d a0, a1, a2, b_, b0, b1, c0; };
T AI Loads load(const double* p, int i) {
    return {_mm512_loadu_pd(p + i), _mm512_loadu_pd(p + i + 1), _mm512_loadu_pd(p + i + 2), _mm512_loadu_pd(p + i + C - 1),
            _mm512_loadu_pd(p + i + C), _mm512_loadu_pd(p + i + C + 1), _mm512_loadu_pd(p + i + 2 * C)};
}
T __attribute__((noinline)) void fused(Data& d, int r) {
    const double* p[3] = {d.x.data(), d.y.data(), d.z.data()};
    float* f = d.out.data();
    for (int c = B; c + 16 <= E; c += 16) {
        const int i = r * C + c;
        Loads L[3][2];
        for (int k = 0; k < 3; ++k) { L[k][0] = load(p[k], i); L[k][1] = load(p[k], i + 8); }
#define DIF(k, A, Bm) join(cvt(_mm512_sub_pd(L[k][0].A, L[k][0].Bm)), cvt(_mm512_sub_pd(L[k][1].A, L[k][1].Bm)))
#define DIR(n, A) forces(DIF(0, A, a0), DIF(1, A, a0), DIF(2, A, a0), d.rest.data() + c, 1000.f, f + n * 3 * C + c, f + n * 3 * C + C + c, f + n * 3 * C + 2 * C + c);
        DIR(0, a1) DIR(1, b0) DIR(2, b1) DIR(3, b_)
        for (int k = 0; k < 3; ++k) {
            _mm512_storeu_ps(f + 4 * 3 * C + k * C + c, _mm512_mul_ps(_mm512_set1_ps(5.f), join(second8(L[k][0].a0, L[k][0].a1, L[k][0].a2), second8(L[k][1].a0, L[k][1].a1, L[k][1].a2))));
            // bend down: x_r - 2 x_{r+1} + x_{r+2}
            _mm512_storeu_ps(f + 5 * 3 * C + k * C + c, _mm512_mul_ps(_mm512_set1_ps(5.f), join(second8(L[k][0].a0, L[k][0].b0, L[k][0].c0), second8(L[k][1].a0, L[k][1].b0, L[k][1].c0))));
        }
    }
}

T __attribute__((noinline)) void fused2(Data& d, int r) {
    const double* p[3] = {d.x.data(), d.y.data(), d.z.data()};
    float* f = d.out.data();
    const __m512 kb = _mm512_set1_ps(5.f);
    for (int c = B; c + 16 <= E; c += 16) {
        const int i = r * C + c;
        __m512 dd[4][3];
        for (int k = 0; k < 3; ++k) {
            __m256 h[4][2], bx[2], by[2];
            for (int hh = 0; hh < 2; ++hh) {
                const double* q = p[k] + i + 8 * hh;
                const __m512d a0 = _mm512_loadu_pd(q), a1 = _mm512_loadu_pd(q + 1), b0 = _mm512_loadu_pd(q + C);
                h[0][hh] = cvt(_mm512_sub_pd(a1, a0));
                h[1][hh] = cvt(_mm512_sub_pd(b0, a0));
                h[2][hh] = cvt(_mm512_sub_pd(_mm512_loadu_pd(q + C + 1), a0));
                h[3][hh] = cvt(_mm512_sub_pd(_mm512_loadu_pd(q + C - 1), a0));
                bx[hh] = second8(a0, a1, _mm512_loadu_pd(q + 2));
                by[hh] = second8(a0, b0, _mm512_loadu_pd(q + 2 * C));
            }
            for (int n = 0; n < 4; ++n) dd[n][k] = join(h[n][0], h[n][1]);
            _mm512_storeu_ps(f + 4 * 3 * C + k * C + c, _mm512_mul_ps(kb, join(bx[0], bx[1])));
            _mm512_storeu_ps(f + 5 * 3 * C + k * C + c, _mm512_mul_ps(kb, join(by[0], by[1])));
        }
        for (int n = 0; n < 4; ++n)
            forces(dd[n][0], dd[n][1], dd[n][2], d.rest.data() + c, 1000.f, f + n * 3 * C + c, f + n * 3 * C + C + c, f + n * 3 * C + 2 * C + c);
    }
}
template <class F> double ns_per_row(F f, Data& d) {
    std::vector<double> t;
    for (int rep = 0; rep < 21; ++rep) {
        auto a = std::chrono::steady_clock::now();
        for (int k = 0; k < 4000; ++k) f(d, 1 + (k & 3));
        auto b = std::chrono::steady_clock::now();
        t.push_back(std::chrono::duration<double, std::nano>(b - a).count() / 4000.0);
    }
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}
int main() {
    Data d;
    for (auto* v : {&d.x, &d.y, &d.z}) v->resize(C * R);
    d.rest.assign(C, 0.0079f); d.out.assign(18 * C, 0.f);
    for (int r = 0; r < R; ++r) for (int c = 0; c < C; ++c) {
        const int i = r * C + c;
        d.x[i] = 0.0078 * c + 1e-4 * std::sin(i); d.y[i] = 1.5 - 0.0078 * r + 1e-4 * std::cos(i); d.z[i] = 0.01 * std::sin(0.1 * i);
    }
    // the two must agree bit for bit
    std::vector<float> a, b;
    separate(d, 2); a.assign(d.out.begin(), d.out.end()); d.out.assign(18 * C, 0.f); fused(d, 2); b.assign(d.out.begin(), d.out.end());
    std::printf("fused == separate: %s\n", a == b ? "yes" : "NO");
    d.out.assign(18 * C, 0.f); fused2(d, 2); b.assign(d.out.begin(), d.out.end());
    std::printf("fused2 == separate: %s\n", a == b ? "yes" : "NO");
    const int springs = 6 * ((E - B) / 16 * 16);
    for (int round = 0; round < 5; ++round) {
        const double s = ns_per_row(separate, d), u = ns_per_row(fused, d), v = ns_per_row(fused2, d);
        std::printf("separate %.3f | fused loads %.3f (%.2fx) | differences first %.3f ns per spring or bend (%.2fx)\n", s / springs, u / springs, s / u, v / springs, s / v);
    }
}
