// Running a check once with each of the fast solver's kernels that this CPU runs.
#pragma once

#include "fast_solver.hpp"

#include <catch2/catch.hpp>

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

}  // namespace clothsim::test
