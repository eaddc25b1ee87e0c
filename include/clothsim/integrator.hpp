// The time integrators, as one table: each one's name, accuracy, stability, what its motion holds, what its
// solve reads and reports, and its substep. Settings, the scene fields, the stepper, the stability bound and
// the panel read an integrator's properties here, and MassSpring steps every one but Verlet through its
// `substep` (Verlet runs in the fast solver or on the textbook path, MassSpring::step).
//
// Adding an integrator: its value in `Integrator`, its substep's declaration and its row in kIntegrators
// (this file), its file in src/core/integrators/ defining the substep, and its tests (docs/ARCHITECTURE.md).
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

namespace clothsim {

enum class Integrator {
    Verlet,           // position Verlet with physical damping: second order, symplectic (the default)
    SymplecticEuler,  // semi-implicit Euler: v += h a, x += h v; first order, symplectic
    Rk4,              // classical Runge-Kutta: fourth order, explicit
    ImplicitEuler,    // backward Euler linearised once per step, CG on the spring Jacobian (Baraff-Witkin 1998)
    Xpbd,             // extended position-based dynamics, one iteration per substep, compliance 1/k
    Projective,       // BDF2 solved by projective dynamics on a prefactorised matrix: the stiff-cloth solver
};

// Everything a substep reads and writes (src/core/integrators/integrator_step.hpp).
struct IntegratorContext;
void symplectic_euler_substep(IntegratorContext& context);
void rk4_substep(IntegratorContext& context);
void implicit_euler_substep(IntegratorContext& context);
void xpbd_substep(IntegratorContext& context);
void projective_substep(IntegratorContext& context);

struct IntegratorInfo {
    Integrator id;
    std::string_view name;        // as scene files and the panel write it
    int order;                    // global order of accuracy in the substep
    // Stability (stability.cpp). Explicit springs have a critical substep factor / omega_max (the highest
    // spring frequency: 2 for Verlet, 2 sqrt 2 for RK4, whose real stability interval is longer); implicit
    // springs set none, and only contact, soft clips and damping can bound the substep.
    bool implicit_springs;
    double spring_factor;         // explicit springs: h_crit = factor / omega
    bool explicit_damping;        // its damping term is forward Euler on a decay rate (stability.hpp: DampingForm)
    double damping_limit;         // its damping alone is stable while c h < this (0: no such limit)
    bool soft_clips_implicit;          // soft clips' holds are in its matrix: they bound no substep
    // State::motion: v h (keeps_velocity), or x - x_prev (Verlet's); and whether that is the substep's
    // displacement, which continuous collision sweeps and self-collision counts (RK4's and projective's v h at
    // the substep's end is not).
    bool keeps_velocity;
    bool motion_is_displacement;
    // The solve: iterations and a relative residual reported (MassSpring::last_solver_iterations and
    // _residual), and which of integration.tolerance and integration.iterations it reads.
    bool reports_solve;
    bool reads_tolerance;
    bool reads_iterations;
    std::string_view solve_label;  // the panel's word before its iterations ("CG ")
    void (*substep)(IntegratorContext&);  // null for Verlet
};

// In the order of `Integrator`.
inline constexpr auto kIntegrators = std::to_array<IntegratorInfo>({
    {Integrator::Verlet, "verlet", 2, false, 2.0, false, 0.0, false, false, true, false, false, false, "", nullptr},
    {Integrator::SymplecticEuler, "symplectic-euler", 1, false, 2.0, true, 0.0, false, true, true, false, false, false,
     "", &symplectic_euler_substep},
    // RK4 on a pure decay rate c is stable while c h < 2.785 (its stability region on the real axis).
    {Integrator::Rk4, "rk4", 4, false, 2.8284271247461903, false, 2.785, false, true, false, false, false, false, "",
     &rk4_substep},
    {Integrator::ImplicitEuler, "implicit-euler", 1, true, 0.0, false, 0.0, false, true, true, true, true, false,
     "CG ", &implicit_euler_substep},
    // Springs are projected implicitly; the damping in XPBD's explicit prediction is forward Euler on a decay
    // rate c, stable while c h < 2.
    {Integrator::Xpbd, "xpbd", 1, true, 0.0, false, 2.0, false, true, true, true, false, false, "", &xpbd_substep},
    {Integrator::Projective, "projective", 2, true, 0.0, false, 0.0, true, true, false, true, true, true, "",
     &projective_substep},
});

constexpr const IntegratorInfo& integrator_info(Integrator i) { return kIntegrators[static_cast<std::size_t>(i)]; }
constexpr bool integrator_table_in_order() {
    for (std::size_t i = 0; i < kIntegrators.size(); ++i) {
        if (static_cast<std::size_t>(kIntegrators[i].id) != i) return false;
    }
    return true;
}
static_assert(integrator_table_in_order(), "kIntegrators lists the integrators in the order of the enum");

// What an integrator's solve reads and reports, for the panel, --json and the tests.
constexpr bool reports_solve(Integrator i) { return integrator_info(i).reports_solve; }
constexpr bool uses_tolerance(Integrator i) { return integrator_info(i).reads_tolerance; }
constexpr bool uses_iterations(Integrator i) { return integrator_info(i).reads_iterations; }

}  // namespace clothsim
