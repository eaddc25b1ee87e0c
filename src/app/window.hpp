// The GLFW window and its OpenGL 3.3 core context, loaded through GLAD. Construction either gives a working
// window or throws WindowError with one message a user can act on (no display, no OpenGL 3.3).
//
// Anti-aliasing: the window asks for `samples` samples per pixel (multisampling), falling back to none where
// the display has no such visual. With kAutoSamples it asks for 4, except on a software renderer (Mesa's
// llvmpipe or softpipe, SwiftShader): there every sample is rasterised on the CPU, and 4x MSAA takes 38% of a
// frame of `hanging` (67.8 ms against 42.2 ms a frame, 1280 x 720, docs/APP.md), so auto turns it off there.
#pragma once

#include <glm/vec2.hpp>

#include <stdexcept>
#include <string>

struct GLFWwindow;

namespace clothsim {

class WindowError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Whether a GL_RENDERER string names a renderer that rasterises on the CPU.
bool is_software_renderer(const std::string& renderer);

class Window {
public:
    static constexpr int kAutoSamples = -1;
    Window(glm::ivec2 size, const std::string& title, bool vsync, int samples = kAutoSamples);
    ~Window();
    Window(const Window&) = delete;
    Window& operator=(const Window&) = delete;

    GLFWwindow* get() const { return window_; }
    glm::ivec2 framebuffer_size() const;  // pixels (HiDPI: may exceed the window size)
    glm::ivec2 window_size() const;       // screen coordinates, what cursor positions are in
    float content_scale() const;          // 1 on a standard display, 2 on a typical HiDPI one
    void set_vsync(bool on);
    int samples() const { return samples_; }  // samples per pixel the window got (0: no multisampling)
    const std::string& renderer() const { return renderer_; }  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    bool software() const { return software_; }                // a renderer that rasterises on the CPU
    bool samples_chosen_for_software() const { return auto_off_; }  // auto turned multisampling off

private:
    // Creates the window with `samples` (or with none where the display offers no such visual), makes its
    // context current and loads OpenGL; throws WindowError.
    void open(glm::ivec2 size, const std::string& title, int samples);

    GLFWwindow* window_ = nullptr;
    int samples_ = 0;
    std::string renderer_;
    bool software_ = false;
    bool auto_off_ = false;
};

}  // namespace clothsim
