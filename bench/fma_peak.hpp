// The fused multiply-add peak of one core, measured, so the throughput table can say what fraction of it the
// fast solver's kernel reaches (issue 16).
#pragma once

#include <string>

namespace clothsim::bench {

// Floating-point operations the fast solver does per spring and substep, counted from the kernel's formula
// F = k (|d| - L0) / |d| d, added to one end and subtracted from the other: d = x_b - x_a (3), |d|^2 (5),
// sqrt (1), |d| - L0 (1), k (...) / |d| (2), the product with d (3), the two accumulations (6). The square
// root and the divide count as one each, as in the roofline convention; the per-particle Verlet update is
// not counted (it is per particle, not per spring).
inline constexpr double kFlopsPerSpring = 21.0;

// GFLOP/s of independent single-precision FMA chains on one core in the widest vectors of `kernel` ("avx512":
// 16 lanes, "avx2+fma": 8, else the generic kernel's scalar code with no FMA: 1 lane, 1 flop per operation).
// Runs about `seconds`.
double fma_peak_gflops(const std::string& kernel, double seconds = 0.2);

}  // namespace clothsim::bench
