#include "clothsim/stretch_curve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace clothsim {
namespace {

std::string show(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

}  // namespace

std::string stretch_samples_problem(const std::vector<StretchSample>& samples) {
    if (samples.size() > static_cast<std::size_t>(kMaxStretchSamples)) {
        return std::to_string(samples.size()) + " samples; allowed: at most " + std::to_string(kMaxStretchSamples);
    }
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const StretchSample& s = samples[i];
        const std::string which = "sample " + std::to_string(i + 1) + " [" + show(s.strain) + ", " + show(s.factor) + "]";
        if (!(s.strain > 0.0f && s.strain <= 1.0f)) return which + ": the strain must be in (0, 1]";
        if (i > 0 && !(s.strain > samples[i - 1].strain)) return which + ": the strains must increase";
        if (!(s.factor > 0.0f && s.factor <= 1e4f)) {
            return which + ": the factor (tangent stiffness over material.stretch) must be in (0, 1e4]";
        }
    }
    return "";
}

SpringCurve spring_curve(const std::vector<StretchSample>& samples, double stretch, double linear) {
    SpringCurve c;
    if (!(linear > 0.0)) return c;
    double previous = 1.0;
    for (const StretchSample& s : samples) {
        if (c.knots == static_cast<std::uint32_t>(kMaxStretchSamples)) break;
        c.strain[c.knots] = s.strain;
        c.gain[c.knots] = static_cast<float>((double(s.factor) - previous) * stretch / linear);
        previous = s.factor;
        ++c.knots;
    }
    return c;
}

std::optional<SpringCurve> blended_curve(const SpringCurve& u, const SpringCurve& v, double alpha) {
    SpringCurve c;
    std::uint32_t i = 0, j = 0;
    while (i < u.knots || j < v.knots) {
        // The next knot by strain; equal strains merge into one.
        const bool take_u = i < u.knots && (j >= v.knots || u.strain[i] <= v.strain[j]);
        const bool take_v = j < v.knots && (i >= u.knots || v.strain[j] <= u.strain[i]);
        if (c.knots == static_cast<std::uint32_t>(kMaxStretchSamples)) return std::nullopt;
        c.strain[c.knots] = take_u ? u.strain[i] : v.strain[j];
        const double gain = (take_u ? alpha * double(u.gain[i++]) : 0.0) + (take_v ? (1.0 - alpha) * double(v.gain[j++]) : 0.0);
        c.gain[c.knots++] = static_cast<float>(gain);
    }
    return c;
}

std::string mesh_curve_problem(const StretchCurve& curve) {
    std::vector<float> strains;
    for (const auto* samples : {&curve.u, &curve.v}) {
        for (const StretchSample& s : *samples) strains.push_back(s.strain);
    }
    std::sort(strains.begin(), strains.end());
    const auto distinct = std::unique(strains.begin(), strains.end()) - strains.begin();
    if (distinct <= kMaxStretchSamples) return "";
    return "a mesh cloth's springs mix u and v, so its curve takes at most " + std::to_string(kMaxStretchSamples) +
           " distinct strains in u and v together (this one has " + std::to_string(distinct) + ")";
}

std::array<SpringCurve, kWarpLevels + 1> mesh_curves(const StretchCurve& curve, double stretch_u, double stretch_v) {
    std::array<SpringCurve, kWarpLevels + 1> out{};
    const SpringCurve u = spring_curve(curve.u, stretch_u, stretch_u), v = spring_curve(curve.v, stretch_v, stretch_v);
    if (u.knots == 0 && v.knots == 0) return out;
    for (int level = 0; level <= kWarpLevels; ++level) {
        const double c = double(level) / kWarpLevels;
        const double along_u = stretch_u * c, along_v = stretch_v * (1.0 - c);
        const double alpha = along_u + along_v > 0.0 ? along_u / (along_u + along_v) : c;
        out[static_cast<std::size_t>(level)] = blended_curve(u, v, alpha).value_or(SpringCurve{});
    }
    return out;
}

namespace {

// ARCSim clamps each interpolated entry at 0 and doubles it; pulled along one direction with the other free,
// the stress across vanishes, leaving k0 - k1^2 / k2 (docs/MATERIAL.md, "Wang et al.'s files").
double uniaxial(const std::array<double, 4>& row, bool weft) {
    const double c11 = std::max(row[0], 0.0), c12 = std::max(row[1], 0.0), c22 = std::max(row[2], 0.0);
    const double along = weft ? c22 : c11, across = weft ? c11 : c22;
    return 2.0 * (across > 0.0 ? along - c12 * c12 / across : along);
}

}  // namespace

double wang_stretch(const WangStretching& rows, bool weft) { return uniaxial(rows[0], weft); }

double wang_tension(const WangStretching& rows, bool weft, double strain) {
    const double lambda = 1.0 + strain;
    // ARCSim's strain_value = (w - 1) 6, clamped to [0, 1); warp is the 0-degree row, weft the 90-degree one.
    const double t = std::clamp(strain * 6.0, 0.0, 1.0);
    const std::array<double, 4>& stretched = rows[weft ? 5 : 1];
    std::array<double, 4> row{};
    for (std::size_t i = 0; i < 4; ++i) row[i] = rows[0][i] * (1.0 - t) + stretched[i] * t;
    return lambda * uniaxial(row, weft) * (lambda * lambda - 1.0) / 2.0;
}

std::vector<StretchSample> wang_stretch_samples(const WangStretching& rows, bool weft) {
    constexpr double kKnots[] = {0.01, 0.02, 0.04, 0.08, 0.12, 1.0 / 6.0, 0.25};
    const double s0 = wang_stretch(rows, weft);
    std::vector<StretchSample> out;
    for (std::size_t i = 0; i + 1 < std::size(kKnots); ++i) {
        const double slope = (wang_tension(rows, weft, kKnots[i + 1]) - wang_tension(rows, weft, kKnots[i])) /
                             (kKnots[i + 1] - kKnots[i]);
        out.push_back({static_cast<float>(kKnots[i]), static_cast<float>(slope / s0)});
    }
    return out;
}

}  // namespace clothsim
