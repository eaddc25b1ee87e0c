// Nonlinear stretch: a fabric's tensile curve, piecewise linear in the strain (docs/MATERIAL.md, "Nonlinear
// stretch"). Real fabrics stretch easily at first and stiffen at a few percent (Wang, O'Brien & Ramamoorthi
// 2011 measured it per direction); a linear spring takes one slope.
//
// Two forms of one curve:
//  - StretchCurve, the material's: per direction (warp along u_axis, weft along v_axis), the tangent stiffness
//    as a multiple of material.stretch from each strain on. Below the first sample the slope is
//    material.stretch itself, so the curve scales with it (the panel's stretch slider keeps the shape).
//  - SpringCurve, a structural spring's: the same slopes as knots and gains of a hinge sum, so the force of a
//    spring stretched by e = |d| - L0 is
//        F = k w (e + sum_j r_j max(0, e - eps_j L0))
//    (k w its linear stiffness, eps_j the knots' strains, r_j the added slope past each, relative to k). With
//    no knots it is the linear spring, operation for operation; in compression (e < 0) every term is 0.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {

// One sample of a material curve: from `strain` on (engineering strain, a fraction), the tangent stiffness
// is `factor` x material.stretch.
struct StretchSample {
    float strain = 0.0f;
    float factor = 1.0f;
    bool operator==(const StretchSample&) const = default;
};

// The material's curve along u_axis (warp) and v_axis (weft); an empty list is linear.
struct StretchCurve {
    std::vector<StretchSample> u;
    std::vector<StretchSample> v;
    bool empty() const { return u.empty() && v.empty(); }
    bool operator==(const StretchCurve&) const = default;
};

inline constexpr int kMaxStretchSamples = 8;

// "" when a direction's samples make a curve; else what is wrong, naming the sample: strains increasing
// within (0, 1], factors in (0, 1e4], at most kMaxStretchSamples.
std::string stretch_samples_problem(const std::vector<StretchSample>& samples);

// A structural spring's curve (above). Trivially copyable, compared bit for bit, read in the hot loops.
struct SpringCurve {
    std::uint32_t knots = 0;
    std::array<float, kMaxStretchSamples> strain{};  // eps_j, increasing, > 0
    std::array<float, kMaxStretchSamples> gain{};    // r_j: the slope added past eps_j, relative to k
    bool operator==(const SpringCurve&) const = default;

    // e + sum_j r_j max(0, e - eps_j L0): the stretch the linear spring would need for the same force (m).
    // Every solver path computes it in this order, in its own precision T (no fused multiply-add).
    template <class T>
    T stretch_term(T e, T rest) const {
        T t = e;
        for (std::uint32_t j = 0; j < knots; ++j) {
            const T over = e - rest * T(strain[j]);
            if (over > T(0)) t = t + T(gain[j]) * over;
        }
        return t;
    }
    // The tangent stiffness at strain e / L0 relative to k: 1 + the gains of the knots passed.
    double tangent(double strain_now) const {
        double t = 1.0;
        for (std::uint32_t j = 0; j < knots; ++j) {
            if (strain_now > double(strain[j])) t += double(gain[j]);
        }
        return t;
    }
    // The largest tangent relative to k anywhere on the curve (the stability bound's worst case).
    double steepest() const {
        double t = 1.0, most = 1.0;
        for (std::uint32_t j = 0; j < knots; ++j) most = std::max(most, t += double(gain[j]));
        return most;
    }
    // The energy 0.5 k w (e^2 + sum_j r_j max(0, e - eps_j L0)^2) over k w: the integral of stretch_term.
    double energy_term(double e, double rest) const {
        double u = 0.5 * e * e;
        for (std::uint32_t j = 0; j < knots; ++j) {
            const double over = e - rest * double(strain[j]);
            if (over > 0.0) u += 0.5 * double(gain[j]) * over * over;
        }
        return u;
    }
};

// A mesh cloth's edge spring (cloth_mesh.hpp) is as stiff as E_u c + E_v (1 - c) times its geometry, for
// c = cos^2 of its rest direction's angle to u_axis: each direction's part follows that direction's curve, so
// its stretch term is alpha T_u(e) + (1 - alpha) T_v(e) with alpha = E_u c / (E_u c + E_v (1 - c)), the warp's
// share of its stiffness. The springs carry the whole membrane there (van Gelder), so each direction's gains are
// m_j - m_(j-1). c is rounded to kWarpLevels-ths (Spring::warp_level), one blend per level.
inline constexpr int kWarpLevels = 32;
// That blend as one hinge sum: both curves' knots, gains alpha r_u and (1 - alpha) r_v, merged where the strains
// are equal (Wang et al.'s samples share theirs). Empty when the knots do not fit kMaxStretchSamples.
std::optional<SpringCurve> blended_curve(const SpringCurve& u, const SpringCurve& v, double alpha);
// "" when a mesh cloth can take the curve: at most kMaxStretchSamples distinct strains in u and v together.
std::string mesh_curve_problem(const StretchCurve& curve);
// A mesh cloth's curves, one per warp level (level L blends at c = L / kWarpLevels), for `stretch` = E_u, E_v.
std::array<SpringCurve, kWarpLevels + 1> mesh_curves(const StretchCurve& curve, double stretch_u, double stretch_v);

// A material direction's samples as a spring's curve: the spring's linear stiffness carries `linear` of the
// membrane's tangent `stretch` (N/m; the rest comes from the diagonals), so a tangent factor m adds
// (m - 1) stretch to it, a gain of (m - 1) stretch / linear. Empty when `linear` is 0.
SpringCurve spring_curve(const std::vector<StretchSample>& samples, double stretch, double linear);

// Wang et al. 2011's stretching data as ARCSim reads it (docs/MATERIAL.md): six rows (c11, c12, c22, c33) in N/m,
// the first at zero strain, the others at a principal stretch of 7/6 along 0, 22.5, 45, 67.5 and 90 degrees from
// warp.
using WangStretching = std::array<std::array<double, 4>, 6>;
// Their fitted model pulled along warp (`weft` false) or weft with the other direction free: the tension per
// width T(e) = lambda S(lambda) (lambda^2 - 1) / 2 at lambda = 1 + e, S the uniaxial stiffness
// 2 (c11 - c12^2 / c22) (or 2 (c22 - c12^2 / c11)) of the row interpolated linearly in lambda between the zero-strain
// row and that direction's, held past 7/6, each entry clamped at 0 (ARCSim's dde.cpp, evaluate_stretching_sample).
double wang_tension(const WangStretching& rows, bool weft, double strain);
// The zero-strain uniaxial stiffness S(1) (N/m): the preset's material.stretch.
double wang_stretch(const WangStretching& rows, bool weft);
// That curve as samples at strains 1, 2, 4, 8, 12 and 16.7%: each segment's slope (to the next, the last to 25%)
// over the zero-strain stiffness.
std::vector<StretchSample> wang_stretch_samples(const WangStretching& rows, bool weft);

}  // namespace clothsim
