// Which particles and cells of the rows x cols grid belong to the cloth (cloth.shape, settings.hpp).
#pragma once

#include "clothsim/settings.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace clothsim {

struct ShapeMask {
    int rows = 0, cols = 0;
    // A cell (r, c) spans particles (r, c) to (r + 1, c + 1): it is part of the cloth when all four corners
    // are inside the outline. A particle is part of the cloth when it is a corner of such a cell; a grid of
    // one row or column (no cells) keeps every particle.
    std::vector<std::uint8_t> particle;  // rows x cols
    std::vector<std::uint8_t> cell;      // (rows - 1) x (cols - 1)
    std::size_t cell_count = 0;
    std::size_t particle_count = 0;

    bool has_particle(int r, int c) const {
        return r >= 0 && r < rows && c >= 0 && c < cols && particle[static_cast<std::size_t>(r) * cols + c];
    }
    bool has_cell(int r, int c) const {
        return r >= 0 && r + 1 < rows && c >= 0 && c + 1 < cols && cell[static_cast<std::size_t>(r) * (cols - 1) + c];
    }
};

// Rectangle: every particle and cell. Disc: the particles inside the grid's inscribed ellipse (a circle on a
// square cloth), centred on the grid, and the cells they complete.
ShapeMask shape_mask(const ClothSettings& cloth);

}  // namespace clothsim
