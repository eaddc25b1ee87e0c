// The GLFW window and its OpenGL 3.3 core context, loaded through GLAD. Construction either gives a working
// window or throws WindowError with one message a user can act on (no display, no OpenGL 3.3).
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

class Window {
public:
    Window(glm::ivec2 size, const std::string& title, bool vsync);
    ~Window();
    Window(const Window&) = delete;
    Window& operator=(const Window&) = delete;

    GLFWwindow* get() const { return window_; }
    glm::ivec2 framebuffer_size() const;  // pixels (HiDPI: may exceed the window size)
    glm::ivec2 window_size() const;       // screen coordinates, what cursor positions are in
    float content_scale() const;          // 1 on a standard display, 2 on a typical HiDPI one
    void set_vsync(bool on);
    int samples() const { return samples_; }

private:
    GLFWwindow* window_ = nullptr;
    int samples_ = 0;
};

}  // namespace clothsim
