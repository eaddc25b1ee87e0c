#include "clothsim/drape.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace clothsim {

DrapeFigures measure_drape(const MassSpring& sim, glm::dvec3 axis, double support_radius, int pixels) {
    DrapeFigures out;
    const State& st = sim.state();
    const Topology& t = sim.topology();
    out.specimen_area = sim.rest_area();
    out.support_area = std::numbers::pi * support_radius * support_radius;
    // The window: a square around the axis reaching the farthest particle (absent slots excluded).
    double reach = support_radius;
    for (std::size_t i = 0; i < st.size(); ++i) {
        if (st.pinned[i] == kAbsent) continue;
        reach = std::max(reach, std::hypot(st.position.x[i] - axis.x, st.position.z[i] - axis.z));
    }
    reach *= 1.001;
    const double pixel = 2.0 * reach / pixels;
    std::vector<std::uint8_t> shadow(static_cast<std::size_t>(pixels) * pixels, 0);
    auto to_pixel = [&](std::uint32_t i) {
        return glm::dvec2((st.position.x[i] - axis.x + reach) / pixel, (st.position.z[i] - axis.z + reach) / pixel);
    };
    // Each triangle fills the pixels whose centres it covers (edge functions, either winding).
    for (const auto& tri : t.triangles) {
        const glm::dvec2 a = to_pixel(tri[0]), b = to_pixel(tri[1]), c = to_pixel(tri[2]);
        const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        if (!(std::abs(area) > 0.0)) continue;
        const double sign = area > 0.0 ? 1.0 : -1.0;
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
        const int x1 = std::min(pixels - 1, static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
        const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
        const int y1 = std::min(pixels - 1, static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
        auto edge = [&](glm::dvec2 p, glm::dvec2 q, glm::dvec2 r) {
            return sign * ((q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x));
        };
        for (int y = y0; y <= y1; ++y) {
            for (int x = x0; x <= x1; ++x) {
                const glm::dvec2 p(x + 0.5, y + 0.5);
                if (edge(a, b, p) >= 0.0 && edge(b, c, p) >= 0.0 && edge(c, a, p) >= 0.0) {
                    shadow[static_cast<std::size_t>(y) * pixels + x] = 1;
                }
            }
        }
    }
    // Area, and the outline's radius per one-degree sector.
    std::vector<double> outline(360, 0.0);
    std::size_t covered = 0;
    for (int y = 0; y < pixels; ++y) {
        for (int x = 0; x < pixels; ++x) {
            if (!shadow[static_cast<std::size_t>(y) * pixels + x]) continue;
            ++covered;
            const double dx = (x + 0.5) * pixel - reach, dz = (y + 0.5) * pixel - reach;
            const double angle = std::atan2(dz, dx) * 180.0 / std::numbers::pi;
            const int sector = (static_cast<int>(std::floor(angle)) + 360) % 360;
            outline[sector] = std::max(outline[sector], std::hypot(dx, dz));
        }
    }
    out.shadow_area = double(covered) * pixel * pixel;
    const double ring = out.specimen_area - out.support_area;
    out.drape_coefficient = ring > 0.0 ? (out.shadow_area - out.support_area) / ring : 0.0;
    // Folds: the smoothed outline rises through its mean once per node. A band of a fifth of the outline's
    // range around the mean (hysteresis) keeps the grid's stair-stepped outline from counting as folds, and
    // an outline that varies by under 5% of its radius (a flat or evenly hanging sheet; the stair steps of a
    // flat disc span 3% at 41 particles a side) has none.
    std::vector<double> smooth(360, 0.0);
    for (int s = 0; s < 360; ++s) {
        for (int k = -7; k <= 7; ++k) smooth[s] += outline[(s + k + 360) % 360] / 15.0;
    }
    double mean = 0.0, low = smooth[0], high = smooth[0];
    for (double r : smooth) mean += r / 360.0, low = std::min(low, r), high = std::max(high, r);
    out.outline_min = low, out.outline_max = high;
    if (high - low < 0.05 * high) return out;
    const double band = 0.1 * (high - low);
    const int start = static_cast<int>(std::min_element(smooth.begin(), smooth.end()) - smooth.begin());
    bool above = false;
    for (int k = 1; k <= 360; ++k) {
        const double r = smooth[(start + k) % 360];
        if (!above && r > mean + band) {
            above = true;
            ++out.folds;
        } else if (above && r < mean - band) {
            above = false;
        }
    }
    return out;
}

}  // namespace clothsim
