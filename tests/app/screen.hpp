// What the tests see of the app's window: screenshots loaded as RGB images, and where a point of the scene
// lands in a 1280 x 720 window with the panel on the left (content scale 1 under Xvfb), exactly as the app
// computes it. Shared by the render and the interactive tests.
#pragma once

#include "camera.hpp"
#include "layout.hpp"

#include "clothsim/mass_spring.hpp"

#include <stb_image.h>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace clothsim::test {

inline constexpr int kWidth = 1280;
inline constexpr int kHeight = 720;
inline const std::string kSize = "1280x720";
struct Rgb {
    int r = 0, g = 0, b = 0;
};

struct Image {
    int width = 0;
    int height = 0;
    std::vector<unsigned char> rgb;  // row-major from the top-left, 3 bytes a pixel

    bool empty() const { return rgb.empty(); }
    Rgb at(int x, int y) const {
        const unsigned char* p = &rgb[3 * (static_cast<std::size_t>(y) * width + x)];
        return {p[0], p[1], p[2]};
    }
    bool contains(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
};

inline Image load_png(const fs::path& path) {
    Image image;
    int channels = 0;
    stbi_set_flip_vertically_on_load(0);
    unsigned char* data = stbi_load(path.string().c_str(), &image.width, &image.height, &channels, 3);
    if (!data) return {};
    image.rgb.assign(data, data + static_cast<std::size_t>(image.width) * image.height * 3);
    stbi_image_free(data);
    return image;
}

struct Rect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1)
    long long area() const { return static_cast<long long>(std::max(x1 - x0, 0)) * std::max(y1 - y0, 0); }
    bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
};

// The window of a --size 1280x720 run: the panel on the left, the 3D view right of it (content scale 1 under
// Xvfb), exactly as the app computes them.
inline const glm::vec4 kView = clothsim::view_rect(glm::vec2(kWidth, kHeight), clothsim::kPanelWidth);
inline const Rect kViewRect{static_cast<int>(kView.x), 0, kWidth, kHeight};
inline const Rect kPanelRect{0, 0, static_cast<int>(clothsim::kPanelWidth), kHeight};

// The camera the app starts with: framed on the scene's initial state, for the view's aspect.
inline clothsim::OrbitCamera start_camera(const clothsim::MassSpring& initial) {
    glm::vec3 lo, hi;
    clothsim::scene_bounds(initial, lo, hi);
    return clothsim::framed_camera(lo, hi, kView.z / kView.w);
}

// A point in the screenshot (pixels from the top-left of the window; z the depth, in [0, 1] when visible).
inline glm::vec3 to_screen(const clothsim::OrbitCamera& camera, glm::vec3 p) {
    glm::vec3 s = clothsim::project(camera, p, glm::vec2(kView.z, kView.w));
    s.x += kView.x;
    s.y += kView.y;
    return s;
}

// Pixels of `r` whose colours in `a` and `b` differ by more than `threshold` (sum over R, G and B).
inline long long differing_pixels(const Image& a, const Image& b, Rect r, int threshold) {
    long long n = 0;
    for (int y = r.y0; y < r.y1; ++y) {
        for (int x = r.x0; x < r.x1; ++x) {
            const Rgb p = a.at(x, y), q = b.at(x, y);
            n += std::abs(p.r - q.r) + std::abs(p.g - q.g) + std::abs(p.b - q.b) > threshold;
        }
    }
    return n;
}

}  // namespace clothsim::test
