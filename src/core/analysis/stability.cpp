#include "clothsim/stability.hpp"

#include "model/forces.hpp"
#include "model/gaussian_curvature.hpp"
#include "model/membrane.hpp"
#include "collision/penalty_contact.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <string>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

namespace clothsim {
namespace {

// The largest h with w h < factor sqrt(1 - d(h)/2) for the per-step damping d(h) (docs/STABILITY.md),
// found by bisection: the left side grows with h, the right side does not.
//  - position Verlet as clothsim writes it (a h^2 divided by 1 + c h/2): the damping terms cancel and the
//    limit is w h < 2 exactly, so d = 0 here;
//  - symplectic Euler with explicit damping: w h < 2 sqrt(1 - c h / 2), so d = c h;
//  - RK4: w h < 2 sqrt(2) (its undamped limit on the imaginary axis; damping only widens it slightly).
enum class DampingForm { None, Explicit };
double critical(double omega, double damping, double factor, DampingForm form) {
    if (!(omega > 0.0)) return std::numeric_limits<double>::infinity();
    auto stable = [&](double h) {
        const double d = form == DampingForm::Explicit ? damping * h : 0.0;
        const double margin = 1.0 - 0.5 * d;
        return margin > 0.0 && omega * h < factor * std::sqrt(margin);
    };
    double lo = 0.0, hi = factor / omega;  // undamped limit: the damped one is never larger
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (stable(mid) ? lo : hi) = mid;
    }
    return lo;
}

}  // namespace

StabilityLimit stability_limit(const Topology& topology, const State& state, const SimulationSettings& settings) {
    StabilityLimit limit;
    const Integrator integrator = settings.integration.integrator;
    const double c = settings.springs.damping;
    // Penalty contact (penalty_contact.hpp): its stiffness at depth p is 3 k_c p^2 / t^2, bounded by its value
    // at p = t, 3 k_c, per enabled collider. It acts on the particle alone (the collider does not move), a
    // diagonal term of the stiffness matrix, so it adds to w^2 at most that bound over the particle's mass
    // (Gershgorin for the row sum; Weyl's inequality for the plane-wave bound, which holds for any diagonal
    // added to the springs'). The integrators that treat springs implicitly take contact explicitly, in their
    // force (implicit Euler) or prediction (XPBD): symplectic Euler's limit w_c h < 2 on the contact alone.
    const ColliderSettings& colliders = settings.colliders;
    const bool penalty = colliders.contact == ContactModel::Penalty && colliders.thickness > 0.0f;
    const double contact_k = penalty ? contact_stiffness_bound(colliders) : 0.0;
    double lightest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (!state.pinned[i]) lightest = std::min(lightest, static_cast<double>(state.mass[i]));
    }
    const double contact_substep = contact_k > 0.0 && std::isfinite(lightest)
                                       ? critical(std::sqrt(contact_k / lightest), c, 2.0, DampingForm::None)
                                       : std::numeric_limits<double>::infinity();
    // Soft clips' holds: a zero-length spring to a fixed anchor adds k to its particle's diagonal alone, as
    // contact does. Every integrator but projective takes it explicitly, like contact; projective has it in its
    // matrix (projective.hpp).
    double hold_rate = 0.0;  // the largest k / m of a hold (1/s^2)
    for (const SoftClipSpring& h : topology.clip_springs) {
        if (!state.pinned[h.particle]) hold_rate = std::max(hold_rate, double(h.stiffness) / state.mass[h.particle]);
    }
    const double hold_substep = hold_rate > 0.0 ? critical(std::sqrt(hold_rate), c, 2.0, DampingForm::None)
                                                : std::numeric_limits<double>::infinity();
    const double explicit_substep = std::min(contact_substep, hold_substep);
    const StabilityBound explicit_bound = hold_substep < contact_substep ? StabilityBound::SoftClips : StabilityBound::Contact;
    // The integrator's row (integrator.hpp) says how its springs, damping and soft clips bound the substep.
    const IntegratorInfo& info = integrator_info(integrator);
    if (info.implicit_springs) {
        // Springs implicit: contact (and soft clips, unless they are in the solver's matrix) are taken
        // explicitly, and an explicit damping term is stable while c h < its limit.
        double substep = info.soft_clips_implicit ? contact_substep : explicit_substep;
        StabilityBound bound = info.soft_clips_implicit ? StabilityBound::Contact : explicit_bound;
        if (info.damping_limit > 0.0) {
            const double damping_substep = c > 0.0 ? info.damping_limit / c : std::numeric_limits<double>::infinity();
            if (damping_substep <= substep) bound = StabilityBound::Damping;
            substep = std::min(damping_substep, substep);
        }
        limit.critical_substep = limit.plane_wave_substep = limit.at_strain_substep = substep;
        limit.bound = bound;
        limit.unconditionally_stable = !std::isfinite(substep);
        limit.wind_substep = std::numeric_limits<double>::infinity();
        return limit;
    }
    std::vector<double> row_sum(state.size(), 0.0);
    // A curved spring (stretch_curve.hpp) counts with the steepest tangent of its curve, so that the bound holds
    // at any strain the cloth reaches; `at_strain` holds what its row sums lose at the tangent of the strain it has
    // now (the at_strain_substep reported beside the bound).
    double steepest_tangent = 1.0;
    std::vector<double> at_strain;
    for (const Spring& s : topology.springs) {
        const double k = stiffness_of(settings.springs, s);
        const SpringCurve& curve = curve_of(settings.springs, s);
        double worst = 1.0;
        if (curve.knots && s.rest_length > 0.0f) {
            if (at_strain.empty()) at_strain.assign(state.size(), 0.0);
            const double strain = glm::length(state.position.get(s.b) - state.position.get(s.a)) / s.rest_length - 1.0;
            worst = curve.steepest();
            steepest_tangent = std::max(steepest_tangent, worst);
            const double lost = 2.0 * k * (curve.tangent(strain) - worst);
            at_strain[s.a] += lost;
            at_strain[s.b] += lost;
        }
        row_sum[s.a] += 2.0 * k * worst;
        row_sum[s.b] += 2.0 * k * worst;
    }
    // A bend's Hessian k w [1 -2 1]^T [1 -2 1] (x I): absolute row sums 4 k w on a and b, 8 k w on m.
    for (const Bend& b : topology.bends) {
        const double k = stiffness_of(settings.springs, b);
        row_sum[b.a] += 4.0 * k;
        row_sum[b.m] += 8.0 * k;
        row_sum[b.b] += 4.0 * k;
    }
    // A hinge's Hessian k c c^T: absolute row sums k |c_i| sum_j |c_j|.
    for (const Hinge& h : topology.hinges) {
        const double k = stiffness_of(settings.springs, h);
        const double total = std::abs(double(h.c[0])) + std::abs(double(h.c[1])) + std::abs(double(h.c[2])) +
                             std::abs(double(h.c[3]));
        for (int i = 0; i < 4; ++i) row_sum[h.v[i]] += k * std::abs(double(h.c[i])) * total;
    }
    // A membrane triangle's Hessian at small strain, block (i, j) = A (C11 bu_i bu_j n_u n_u^T + C22 bv_i bv_j n_v n_v^T
    // + C12 (bu_i bv_j n_u n_v^T + bv_i bu_j n_v n_u^T) + C66 (bu_i n_v + bv_i n_u)(bu_j n_v + bv_j n_u)^T): each
    // rank-one term's norm bounds its share of the block's, a curved direction at its steepest tangent.
    if (!topology.membranes.empty()) {
        const MembraneTensor tensor = membrane_tensor(settings.springs);
        const double tu = settings.springs.membrane_curve[0].steepest(), tv = settings.springs.membrane_curve[1].steepest();
        steepest_tangent = std::max({steepest_tangent, tu, tv});
        for (const Membrane& m : topology.membranes) {
            double su = 0.0, sv = 0.0;  // sum_j |bu_j|, sum_j |bv_j|
            for (int j = 0; j < 3; ++j) su += std::abs(double(m.bu[j])), sv += std::abs(double(m.bv[j]));
            for (int i = 0; i < 3; ++i) {
                const double bu = std::abs(double(m.bu[i])), bv = std::abs(double(m.bv[i]));
                row_sum[m.v[i]] += double(m.area) * (tensor.c11 * tu * bu * su + tensor.c22 * tv * bv * sv +
                                                     tensor.c12 * (bu * sv + bv * su) + tensor.c66 * (bu + bv) * (su + sv));
            }
        }
    }
    // The Gaussian-curvature term (gaussian_curvature.hpp): c times a rim corner's angle, whose Hessian's blocks are
    // of size 1 / (|e_i| |e_j|) for a triangle of good shape: 4 |c| (1/|e_1| + 1/|e_2|)^2 on each of its corners.
    if (has_gaussian_term(topology, settings.springs)) {
        const double coefficient = std::abs(gaussian_coefficient(topology.gaussian, settings.springs));
        for (const auto& corner : topology.gaussian.rim_corners) {
            const glm::dvec3 xa = state.position.get(corner[0]);
            const double l1 = glm::length(state.position.get(corner[1]) - xa), l2 = glm::length(state.position.get(corner[2]) - xa);
            if (!(l1 > 0.0) || !(l2 > 0.0)) continue;
            const double r = 4.0 * coefficient * (1.0 / l1 + 1.0 / l2) * (1.0 / l1 + 1.0 / l2);
            for (std::uint32_t i : corner) row_sum[i] += r;
        }
    }
    for (const SoftClipSpring& h : topology.clip_springs) row_sum[h.particle] += h.stiffness;
    double gershgorin = 0.0, gershgorin_now = 0.0;
    for (std::size_t i = 0; i < state.size(); ++i) {
        if (state.pinned[i]) continue;
        gershgorin = std::max(gershgorin, (row_sum[i] + contact_k) / state.mass[i]);
        const double now = at_strain.empty() ? row_sum[i] : row_sum[i] + at_strain[i];
        gershgorin_now = std::max(gershgorin_now, (now + contact_k) / state.mass[i]);
    }
    const SpringSettings& k = settings.springs;
    // A line of springs k has w^2 up to 4 k / m, a line of bends up to 16 k / m (the symbol (2 - 2 cos)^2).
    const double bending = std::max(k.bending.x, k.bending.y) * (topology.bends.empty() ? 1.0 : 4.0);
    const double sum_k = double(std::max(k.structural.x, k.structural.y)) * steepest_tangent + double(k.shear) + bending;
    limit.omega_gershgorin = std::sqrt(gershgorin);
    limit.omega_plane_wave = std::isfinite(lightest) ? std::sqrt((4.0 * sum_k + contact_k) / lightest + hold_rate) : 0.0;
    // A mesh cloth has no grid lines for a plane wave to run along, and its settings hold moduli, not springs'
    // k: its bound is the Gershgorin one.
    if (topology.mesh) limit.omega_plane_wave = limit.omega_gershgorin;
    const double factor = info.spring_factor;
    const DampingForm form = info.explicit_damping ? DampingForm::Explicit : DampingForm::None;
    limit.critical_substep = critical(limit.omega_gershgorin, settings.springs.damping, factor, form);
    limit.at_strain_substep = critical(std::sqrt(gershgorin_now), settings.springs.damping, factor, form);
    limit.plane_wave_substep = critical(limit.omega_plane_wave, settings.springs.damping, factor, form);
    // Wind pressure on a particle's share of the area is a drag, F ~ drag A |w_rel| w_rel, whose rate
    // 2 drag A |w_rel| / m an explicit step must keep below about 1 per substep (forward Euler's limit on
    // a decay rate is 2; half of it leaves room for the gusts and for the cloth's own speed).
    limit.wind_substep = std::numeric_limits<double>::infinity();
    const ForceSettings& f = settings.forces;
    const double wind_speed = glm::length(glm::dvec3(f.wind)) * (1.0 + f.gust_strength);
    if (wind_speed > 0.0 && f.drag > 0.0f && std::isfinite(lightest) && state.size() > 0) {
        double area = 0.0;
        for (const auto& t : topology.triangles) {
            const glm::dvec3 a = state.position.get(t[0]);
            area += 0.5 * glm::length(glm::cross(state.position.get(t[1]) - a, state.position.get(t[2]) - a));
        }
        const double share = f.wind_model == WindModel::Uniform ? area / double(state.size())
                                                                 : 6.0 * area / (3.0 * double(state.size()));
        const double rate = 2.0 * f.drag * share * wind_speed / lightest;
        if (rate > 0.0) limit.wind_substep = 1.0 / rate;
    }
    limit.critical_substep = std::min(limit.critical_substep, limit.wind_substep);
    limit.at_strain_substep = std::min(limit.at_strain_substep, limit.wind_substep);
    limit.plane_wave_substep = std::min(limit.plane_wave_substep, limit.wind_substep);
    if (info.damping_limit > 0.0 && c > 0.0) {
        // Its damping alone (RK4 on a pure decay rate c: c h < 2.785, its stability region on the real axis).
        limit.critical_substep = std::min(limit.critical_substep, info.damping_limit / c);
        limit.at_strain_substep = std::min(limit.at_strain_substep, info.damping_limit / c);
        limit.plane_wave_substep = std::min(limit.plane_wave_substep, info.damping_limit / c);
    }
    return limit;
}

double xpbd_rigid_stiffness(double inverse_mass_sum, double substep) {
    return 10.0 / (inverse_mass_sum * substep * substep);
}

StabilityLimit stability_limit(const MassSpring& sim) {
    return stability_limit(sim.topology(), sim.state(), sim.settings());
}

int auto_substeps(const StabilityLimit& limit, float dt, float safety, int minimum) {
    if (!std::isfinite(limit.critical_substep) || !(limit.critical_substep > 0.0)) return std::max(minimum, 1);
    const double wanted = std::ceil(double(dt) / (double(safety) * limit.critical_substep));
    return static_cast<int>(std::clamp(wanted, double(std::max(minimum, 1)), double(kMaxSubsteps)));
}

double max_strain(const MassSpring& sim) {
    double worst = 0.0;
    const std::optional<std::size_t> grabbed = sim.grabbed();
    for (const Spring& s : sim.topology().springs) {
        if (s.rest_length == 0.0f) continue;
        if (grabbed && (s.a == *grabbed || s.b == *grabbed)) continue;  // the user's pull, not a blow-up
        // Between two pins: its length is where the user put the pins (a dragged pin), never the dynamics'.
        if (sim.state().pinned[s.a] == kPinned && sim.state().pinned[s.b] == kPinned) continue;
        if (stiffness_of(sim.settings().springs, s) == 0.0f) continue;  // exerts no force: not a spring
        const double length = glm::length(glm::dvec3(sim.position(s.b)) - glm::dvec3(sim.position(s.a)));
        if (!std::isfinite(length)) return std::numeric_limits<double>::infinity();
        worst = std::max(worst, length / s.rest_length - 1.0);
    }
    return worst;
}

const char* blow_up_name(BlowUp cause) {
    switch (cause) {
        case BlowUp::None: return "";
        case BlowUp::NonFinite: return "non-finite positions";
        case BlowUp::Strain: return "max strain above the bound";
        case BlowUp::Energy: return "energy jump above the bound";
    }
    return "";
}

StepCheck check_step(const MassSpring& sim, double energy_before, const GuardSettings& guard) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    if (!sim.all_finite()) return {BlowUp::NonFinite, kInf};
    const double energy = sim.energy().total();
    if (max_strain(sim) > guard.max_strain) return {BlowUp::Strain, energy};
    const bool energy_ok = std::isfinite(energy) &&
                           energy - energy_before <= guard.max_energy_growth * (std::fabs(energy_before) + 1.0);
    return {energy_ok ? BlowUp::None : BlowUp::Energy, energy};
}

namespace {

// What the stability bound asks of the cloth as it is: the substeps a step needs and the stiffest spring kind,
// for the guard's message ("the springs (structural 1e+09 N/m) need 73000 substeps per step").
std::string what_bounds(const MassSpring& sim) {
    const StabilityLimit limit = stability_limit(sim);
    if (limit.unconditionally_stable || !(limit.critical_substep > 0.0)) return "";
    const SpringSettings& k = sim.settings().springs;
    const double structural = std::max(k.structural.x, k.structural.y), bending = std::max(k.bending.x, k.bending.y);
    const char* kind = structural >= k.shear && structural >= bending ? "structural" : k.shear >= bending ? "shear" : "bending";
    const double stiffest = std::max({structural, double(k.shear), bending});
    const double needed = std::ceil(sim.settings().integration.dt / limit.critical_substep);
    char text[200];
    if (limit.bound == StabilityBound::Springs) {
        std::snprintf(text, sizeof text, "; the springs (%s k = %.3g N/m) need %.0f substeps per step (substep %.3g s)",
                      kind, stiffest, needed, limit.critical_substep);
    } else {
        std::snprintf(text, sizeof text, "; the %s need %.0f substeps per step (substep %.3g s)",
                      limit.bound == StabilityBound::Damping ? "damping" : limit.bound == StabilityBound::SoftClips ? "soft clips" : "penalty contact",
                      needed, limit.critical_substep);
    }
    return text;
}

}  // namespace

// One message a step that needed the guard: what blew up, what held (or that nothing did, and what the
// stability bound asks for).
bool run_guarded(MassSpring& sim, long long steps, const GuardSettings& guard, std::string& log) {
    std::optional<MassSpring> last_good;
    return run_guarded(sim, steps, guard, log, last_good);
}

bool run_guarded(MassSpring& sim, long long steps, const GuardSettings& guard, std::string& log,
                 std::optional<MassSpring>& last_good) {
    double energy_after = std::numeric_limits<double>::quiet_NaN();  // the last step's, when it held
    for (long long done = 0; done < steps; ++done) {
        if (sim.asleep()) {  // asleep with nothing to wake it: the step moves nothing, there is nothing to check
            sim.run_steps(1);
            energy_after = std::numeric_limits<double>::quiet_NaN();
            continue;
        }
        // The last good state, copied into the buffers of the one before (MassSpring's copy assignment keeps
        // them): a fresh copy per step cost page faults.
        if (last_good) *last_good = sim;
        else last_good.emplace(sim);
        const MassSpring& good = *last_good;
        // Nothing changes the cloth between two steps of this loop: the energy after one is the next one's before.
        const double energy_before = std::isnan(energy_after) ? good.energy().total() : energy_after;
        const int first = sim.settings().integration.substeps;
        BlowUp first_cause = BlowUp::None;
        for (int retries = 0;; ++retries) {
            sim.run_steps(1);
            const StepCheck check = check_step(sim, energy_before, guard);
            const BlowUp blow_up = check.blow_up;
            if (blow_up == BlowUp::None) {
                energy_after = check.energy;
                if (retries > 0) {
                    char line[256];
                    std::snprintf(line, sizeof line,
                                  "guard: t = %.4g s: the step blew up (%s) at %d substeps; rolled back, it held at "
                                  "%d\n",
                                  good.time(), blow_up_name(first_cause), first, sim.settings().integration.substeps);
                    log += line;
                }
                break;
            }
            if (first_cause == BlowUp::None) first_cause = blow_up;
            const int substeps = sim.settings().integration.substeps;
            if (retries >= guard.max_retries || substeps >= kMaxSubsteps) {
                sim = good;
                char line[256];
                std::snprintf(line, sizeof line,
                              "guard: t = %.4g s: the step blew up (%s) at every substep count from %d to %d; rolled back "
                              "and stopped at the last good state",
                              good.time(), blow_up_name(blow_up), first, substeps);
                log += line + what_bounds(sim) + "\n";
                return false;
            }
            sim = good;
            sim.set_substeps(std::min(2 * substeps, kMaxSubsteps));
        }
    }
    return true;
}

}  // namespace clothsim
