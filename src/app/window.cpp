#include "window.hpp"

#include "gl.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstring>

#include <dlfcn.h>
#include <link.h>

namespace clothsim {
namespace {

std::string g_last_glfw_error;  // GLFW reports errors through a callback; keep the last for the message

void on_glfw_error(int, const char* description) { g_last_glfw_error = description ? description : "unknown"; }

}  // namespace

// AddressSanitizer builds only. Mesa unloads its DRI driver (llvmpipe's swrast_dri.so) at exit, and
// LeakSanitizer then reports the ~240 bytes the driver never frees as a leak from an unknown module, which no
// suppression can name (../shared/TOOLCHAIN.md). Marking the driver RTLD_NODELETE keeps it mapped, so the
// report names it and .ci/lsan-gl.supp suppresses exactly that module; every other leak is still reported.
#if defined(__SANITIZE_ADDRESS__)
static int pin_dri_module(struct dl_phdr_info* info, size_t, void*) {
    if (info->dlpi_name && std::strstr(info->dlpi_name, "_dri.so")) {
        dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);  // a reference kept on purpose
    }
    return 0;
}
static void keep_gl_driver_loaded() { dl_iterate_phdr(pin_dri_module, nullptr); }
#else
static void keep_gl_driver_loaded() {}
#endif

Window::Window(glm::ivec2 size, const std::string& title, bool vsync) {
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) {
        throw WindowError("cannot open a window: " + g_last_glfw_error +
                          " (no display: run clothsim --headless, or under xvfb-run)");
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
    // 4x MSAA when the display offers it; a display without multisampled visuals still gets a window.
    for (int samples : {4, 0}) {
        glfwWindowHint(GLFW_SAMPLES, samples);
        window_ = glfwCreateWindow(size.x, size.y, title.c_str(), nullptr, nullptr);
        keep_gl_driver_loaded();  // also when creation failed: the driver was loaded to try
        if (window_) {
            samples_ = samples;
            break;
        }
    }
    if (!window_) {
        const std::string reason = g_last_glfw_error;
        glfwTerminate();
        throw WindowError("cannot create an OpenGL 3.3 core window: " + reason +
                          " (clothsim needs OpenGL 3.3; run clothsim --headless without one)");
    }
    glfwMakeContextCurrent(window_);
    const int version = gladLoadGL(glfwGetProcAddress);
    if (version == 0 || GLAD_VERSION_MAJOR(version) * 10 + GLAD_VERSION_MINOR(version) < 33) {
        glfwDestroyWindow(window_);
        glfwTerminate();
        throw WindowError("OpenGL 3.3 is not available (the driver offers " +
                          (version ? std::to_string(GLAD_VERSION_MAJOR(version)) + "." +
                                         std::to_string(GLAD_VERSION_MINOR(version))
                                   : std::string("nothing GLAD could load")) +
                          "); run clothsim --headless instead");
    }
    set_vsync(vsync);
}

Window::~Window() {
    glfwDestroyWindow(window_);
    glfwTerminate();
}

glm::ivec2 Window::framebuffer_size() const {
    glm::ivec2 s;
    glfwGetFramebufferSize(window_, &s.x, &s.y);
    return s;
}

glm::ivec2 Window::window_size() const {
    glm::ivec2 s;
    glfwGetWindowSize(window_, &s.x, &s.y);
    return s;
}

float Window::content_scale() const {
    float x = 1.0f, y = 1.0f;
    glfwGetWindowContentScale(window_, &x, &y);
    return std::max(x, 1.0f);
}

void Window::set_vsync(bool on) { glfwSwapInterval(on ? 1 : 0); }

}  // namespace clothsim
