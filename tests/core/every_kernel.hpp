// Running a check once with each of the fast solver's kernels that this CPU runs.
#pragma once

#include "integrators/fast_solver.hpp"

#include <catch2/catch.hpp>

#include <initializer_list>
#include <vector>

namespace clothsim::test {

// Runs `check` once with each kernel this CPU runs in use (FastSolver::use_kernel: the spring kernels, grid
// XPBD's and the vertex normals' all follow it), then puts back the one in use before, also when a REQUIRE
// throws.
template <class Check>
void with_every_kernel(Check check) {
    struct Restore {
        FastKernel was;
        ~Restore() { FastSolver::use_kernel(was); }
    };
    const FastKernel best = FastSolver::best_kernel();
    for (FastKernel kernel : {FastKernel::Generic, FastKernel::Avx2, FastKernel::Avx512}) {
        if (static_cast<int>(kernel) > static_cast<int>(best)) continue;  // this CPU cannot run it
        const Restore restore{FastSolver::use_kernel(kernel)};
        REQUIRE(FastSolver::kernel() == kernel);
        check();
    }
}

// The thread counts an every-kernel loop runs. The Release suite runs them all; under the sanitizers (about
// ten times slower) only a team of two, whose code paths include the one thread's (AddressSanitizer sees the
// same accesses either way; the results' equality across counts is the Release suite's check). A team larger
// than the machine's two cores waits at its barriers for descheduled threads: under the sanitizers a team of
// three took twice the time of the three counts together.
inline std::vector<int> thread_counts(std::initializer_list<int> all) {
#if defined(__SANITIZE_ADDRESS__)
    std::vector<int> teams;
    for (int t : all) {
        if (t == 2) teams.push_back(t);
    }
    return teams.empty() ? std::vector<int>(all) : teams;
#else
    return std::vector<int>(all);
#endif
}

}  // namespace clothsim::test
