#include "fma_peak.hpp"

#include <immintrin.h>

#include <algorithm>
#include <chrono>

namespace clothsim::bench {
namespace {

// Ten independent accumulator chains hide the FMA latency (4 cycles, 2 ports: 8 in flight) on the CPUs here.
// Each call does `rounds` x 10 FMAs of `lanes` lanes: 2 flops each.
__attribute__((target("avx512f"))) float chains_avx512(long long rounds) {
    __m512 a[10];
    for (int i = 0; i < 10; ++i) a[i] = _mm512_set1_ps(1.0f + 1e-3f * static_cast<float>(i));
    const __m512 m = _mm512_set1_ps(0.999999f), c = _mm512_set1_ps(1e-7f);
    for (long long r = 0; r < rounds; ++r) {
        for (int i = 0; i < 10; ++i) a[i] = _mm512_fmadd_ps(a[i], m, c);
    }
    __m512 s = a[0];
    for (int i = 1; i < 10; ++i) s = _mm512_add_ps(s, a[i]);
    float out[16];
    _mm512_storeu_ps(out, s);
    float sum = 0.0f;
    for (float v : out) sum += v;
    return sum;
}

__attribute__((target("avx2,fma"))) float chains_avx2(long long rounds) {
    __m256 a[10];
    for (int i = 0; i < 10; ++i) a[i] = _mm256_set1_ps(1.0f + 1e-3f * static_cast<float>(i));
    const __m256 m = _mm256_set1_ps(0.999999f), c = _mm256_set1_ps(1e-7f);
    for (long long r = 0; r < rounds; ++r) {
        for (int i = 0; i < 10; ++i) a[i] = _mm256_fmadd_ps(a[i], m, c);
    }
    __m256 s = a[0];
    for (int i = 1; i < 10; ++i) s = _mm256_add_ps(s, a[i]);
    float out[8];
    _mm256_storeu_ps(out, s);
    return out[0] + out[1] + out[2] + out[3] + out[4] + out[5] + out[6] + out[7];
}

float chains_scalar(long long rounds) {  // a multiply and an add: 2 flops, as an FMA counts
    float a[10];
    for (int i = 0; i < 10; ++i) a[i] = 1.0f + 1e-3f * static_cast<float>(i);
    for (long long r = 0; r < rounds; ++r) {
        for (int i = 0; i < 10; ++i) a[i] = a[i] * 0.999999f + 1e-7f;
    }
    float s = 0.0f;
    for (float v : a) s += v;
    return s;
}

}  // namespace

double fma_peak_gflops(const std::string& kernel, double seconds) {
    const int lanes = kernel == "avx512" ? 16 : kernel == "avx2+fma" ? 8 : 1;
    auto run = [&](long long rounds) {
        return kernel == "avx512" ? chains_avx512(rounds) : kernel == "avx2+fma" ? chains_avx2(rounds)
                                                                                  : chains_scalar(rounds);
    };
    // Grow the round count until one run takes a fifth of the time, then keep the best of five runs.
    long long rounds = 1 << 16;
    volatile float sink = 0.0f;
    using Clock = std::chrono::steady_clock;
    double best = 0.0;
    for (;;) {
        const auto t0 = Clock::now();
        sink = sink + run(rounds);
        const double s = std::chrono::duration<double>(Clock::now() - t0).count();
        if (s >= seconds / 5.0) break;
        rounds *= 2;
    }
    for (int i = 0; i < 5; ++i) {
        const auto t0 = Clock::now();
        sink = sink + run(rounds);
        const double s = std::chrono::duration<double>(Clock::now() - t0).count();
        best = std::max(best, 2.0 * 10.0 * lanes * static_cast<double>(rounds) / s * 1e-9);
    }
    return best;
}

}  // namespace clothsim::bench
