// Stability limits known before stepping, and the guard that recovers when a step blows up anyway.
//
// Position Verlet on a linear spring network is stable iff every mode's w h < 2 sqrt(1 - d/2) in the drag
// form x' = x + (x - x_prev)(1 - d) + a h^2, which damps by a fraction d of the motion per step (Jakobsen,
// "Advanced Character Physics", GDC 2001); in clothsim's central-difference form (a h^2 divided by
// 1 + c h / 2, d = c h / (1 + c h / 2)) the damping cancels and the condition is exactly w h < 2
// (docs/STABILITY.md derives both). The largest mode w_max is bounded two ways:
//  - Gershgorin: w_max^2 <= max_i sum_j 2 k_ij / m_i over particle i's springs. Always safe.
//  - Plane waves on a regular grid: w_max^2 <= 4 (k_struct + k_shear + k_bend) / m. Tighter.
// Penalty contact (colliders.contact = penalty) adds its stiffness bound 3 k_c per enabled collider (its
// stiffness 3 k_c p^2 / t^2 at depth p = t) to each particle's: to the Gershgorin row sum and, over the
// lightest mass, to the plane-wave bound; implicit Euler and XPBD take it explicitly, so it gives them a limit.
// Symplectic Euler has Verlet's limit; RK4's stability region reaches w h = 2 sqrt(2) on the imaginary axis
// (and c h = 2.785 for damping); implicit Euler has no limit; XPBD's only one is its explicitly damped
// prediction, c h < 2. With penalty contact both get w_c h < 2 for the contact alone, w_c^2 = 3 k_c n / m
// (n enabled colliders, m the lightest free particle).
#pragma once

#include "clothsim/mass_spring.hpp"

#include <optional>
#include <string>

namespace clothsim {

// What sets the critical substep: the springs (explicit integrators), or, where the springs are implicit,
// XPBD's explicit damping (c h < 2), penalty contact or soft clips (a force every integrator takes explicitly).
enum class StabilityBound { Springs, Damping, Contact, SoftClips };

struct StabilityLimit {
    double omega_gershgorin = 0.0;  // rad/s, the safe bound on the fastest mode
    double omega_plane_wave = 0.0;  // rad/s, the tighter grid bound
    double critical_substep = 0.0;  // s: the largest stable substep by the Gershgorin bound and wind (inf: none)
    double plane_wave_substep = 0.0;  // s: the same with the plane-wave bound
    // s: critical_substep with each curved spring (stretch_curve.hpp) at the tangent of the strain it has now
    // instead of its curve's steepest; equal to it for a linear cloth. A cloth at rest could step at this
    // substep; the bound is the stretched cloth's.
    double at_strain_substep = 0.0;
    double wind_substep = 0.0;      // s: the explicit limit of the wind's drag, 1 / rate (inf without wind)
    bool unconditionally_stable = false;  // implicit Euler, XPBD
    StabilityBound bound = StabilityBound::Springs;
};

// For the cloth's current stiffness, masses, damping and integrator.
StabilityLimit stability_limit(const MassSpring& sim);

// XPBD's stiffness ceiling: the spring stiffness k (N/m) above which one projection per substep h treats a
// spring as rigid to within 10%. A projection moves the spring's ends by the fraction (w_a + w_b) /
// (w_a + w_b + alpha) of its violation, alpha = 1 / (k h^2) (Macklin, Mueller & Chentanez 2016, eq. 18), which
// is 10/11 at k = 10 / ((w_a + w_b) h^2) and nearer 1 above it: there the single pass, not k, sets the
// stretch, and a stiffer or softer spring projects nearly alike (docs/STIFF_CLOTH.md).
double xpbd_rigid_stiffness(double inverse_mass_sum, double substep);
StabilityLimit stability_limit(const Topology& topology, const State& state, const SimulationSettings& settings);

// Substeps per step that keep dt / substeps below `safety` x the critical substep (at least `minimum`,
// at most kMaxSubsteps, the largest a scene may hold).
int auto_substeps(const StabilityLimit& limit, float dt, float safety, int minimum = 1);

// What the guard checks after each step: every position finite, and no spring stretched beyond
// `max_strain` (|d| / L0 - 1) — a cloth that far from rest has blown up even if it is still finite.
// ... and no jump of total energy by more than `max_energy_growth` x (|E| + 1 J) in one step: a blow-up
// multiplies it by orders of magnitude, wind or a grab adds far less.
struct GuardSettings {
    float max_strain = 10.0f;          // 1000%
    float max_energy_growth = 100.0f;  // see above
    int max_retries = 6;               // each retry doubles the substeps
};

// Why a step fails the guard's check: the first of its three criteria that it breaks.
enum class BlowUp { None, NonFinite, Strain, Energy };

// What each BlowUp is called in the guard's log and the CLI's messages ("" for None).
const char* blow_up_name(BlowUp cause);

// The guard's check of the step just run, from the total energy before it (J). `energy` is the total energy
// after it (J; inf when not finite), the next step's `energy_before`. run_guarded and the headless run
// (src/app/headless.cpp) both call this, so a step one calls a blow-up the other does too.
struct StepCheck {
    BlowUp blow_up = BlowUp::None;
    double energy = 0.0;
};
StepCheck check_step(const MassSpring& sim, double energy_before, const GuardSettings& guard);

// Runs `steps` steps; when a step fails the check it rolls back to the state before that step, doubles
// integration.substeps and retries. Each change is described in `log` (one line each). Returns false when
// the retries ran out (the simulation is then left at the last good state, never NaN).
bool run_guarded(MassSpring& sim, long long steps, const GuardSettings& guard, std::string& log);
// The same, keeping the last good state in `last_good` between calls, whose storage each step reuses.
bool run_guarded(MassSpring& sim, long long steps, const GuardSettings& guard, std::string& log,
                 std::optional<MassSpring>& last_good);

// The largest |d| / L0 - 1 over springs with L0 > 0 (NaN-safe: a non-finite spring counts as infinite),
// leaving out the springs of a grabbed particle and those between two pins (a strain the user imposes, by a
// grab or by dragging a pin, is not a blow-up) and springs of a kind with stiffness 0 (they exert no force).
double max_strain(const MassSpring& sim);

}  // namespace clothsim
