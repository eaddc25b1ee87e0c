// Where things go in the window: the panel on the left, the 3D view in the rest. Shared by the app and by
// the render tests, which project the simulated cloth into the screenshot to check where it was drawn.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include <algorithm>

namespace clothsim {

inline constexpr float kPanelWidth = 440.0f;  // window coordinates at content scale 1: the panel's starting width
inline constexpr float kMinPanelWidth = 300.0f;  // ... and the narrowest a drag of its edge makes it
inline constexpr float kMaxPanelShare = 0.45f;  // of the window's width: a narrow window keeps a 3D view

// The 3D view (x, y from the top-left, width, height) in window coordinates.
inline glm::vec4 view_rect(glm::vec2 window_size, float panel_width) {
    const float x = std::min(panel_width, window_size.x - 1.0f);
    return {x, 0.0f, std::max(window_size.x - x, 1.0f), std::max(window_size.y, 1.0f)};
}

}  // namespace clothsim
