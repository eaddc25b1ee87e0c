#include "scene/cloth_shape.hpp"

namespace clothsim {

ShapeMask shape_mask(const ClothSettings& cloth) {
    ShapeMask m;
    m.rows = cloth.rows;
    m.cols = cloth.cols;
    const std::size_t n = static_cast<std::size_t>(cloth.rows) * cloth.cols;
    const bool cells = cloth.rows > 1 && cloth.cols > 1;
    // Inside the outline, in grid units: the inscribed ellipse's centre and half-axes, a little slack so that
    // the particles on the circle (the ends of the middle row and column) count as inside.
    std::vector<std::uint8_t> inside(n, 1);
    if (cloth.shape == ClothShape::Disc && cells) {
        const double cr = 0.5 * (cloth.rows - 1), cc = 0.5 * (cloth.cols - 1);
        for (int r = 0; r < cloth.rows; ++r) {
            for (int c = 0; c < cloth.cols; ++c) {
                const double y = (r - cr) / cr, x = (c - cc) / cc;
                inside[static_cast<std::size_t>(r) * cloth.cols + c] = x * x + y * y <= 1.0 + 1e-9;
            }
        }
    }
    if (!cells) {
        m.particle = inside;
        m.particle_count = n;
        return m;
    }
    m.cell.assign(static_cast<std::size_t>(cloth.rows - 1) * (cloth.cols - 1), 0);
    m.particle.assign(n, 0);
    auto in = [&](int r, int c) { return inside[static_cast<std::size_t>(r) * cloth.cols + c] != 0; };
    for (int r = 0; r + 1 < cloth.rows; ++r) {
        for (int c = 0; c + 1 < cloth.cols; ++c) {
            if (!(in(r, c) && in(r, c + 1) && in(r + 1, c) && in(r + 1, c + 1))) continue;
            m.cell[static_cast<std::size_t>(r) * (cloth.cols - 1) + c] = 1;
            ++m.cell_count;
            for (int dr = 0; dr < 2; ++dr)
                for (int dc = 0; dc < 2; ++dc) m.particle[static_cast<std::size_t>(r + dr) * cloth.cols + c + dc] = 1;
        }
    }
    for (std::uint8_t p : m.particle) m.particle_count += p;
    return m;
}

}  // namespace clothsim
