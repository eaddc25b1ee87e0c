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

// Renderers that rasterise on the CPU, by their GL_RENDERER strings: Mesa's llvmpipe and softpipe (and the
// classic "Software Rasterizer"), Google's SwiftShader.
bool is_software_renderer(const std::string& renderer) {
    for (const char* name : {"llvmpipe", "softpipe", "Software Rasterizer", "SwiftShader"}) {
        if (renderer.find(name) != std::string::npos) return true;
    }
    return false;
}

Window::Window(glm::ivec2 size, const std::string& title, bool vsync, int samples) {
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
    // Hidden until its samples are settled: the renderer is known only once a context exists, and on a software
    // renderer the automatic choice makes the window again without samples (never shown, so no window
    // manager, screen reader or xdotool sees the first one).
    glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
    const bool automatic = samples == kAutoSamples;
    open(size, title, automatic ? 4 : samples);
    if (automatic && samples_ > 0 && software_) {
        glfwDestroyWindow(window_);
        window_ = nullptr;
        open(size, title, 0);
        auto_off_ = true;
    }
    glfwShowWindow(window_);
    set_vsync(vsync);
}

void Window::open(glm::ivec2 size, const std::string& title, int samples) {
    for (int tried : {samples, 0}) {
        glfwWindowHint(GLFW_SAMPLES, tried);
        window_ = glfwCreateWindow(size.x, size.y, title.c_str(), nullptr, nullptr);
        keep_gl_driver_loaded();  // also when creation failed: the driver was loaded to try
        if (window_) break;
        if (tried == 0) break;
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
    // What the framebuffer got, which a driver may round or ignore (GLFW_SAMPLES is a minimum hint).
    GLint got = 0;
    glGetIntegerv(GL_SAMPLES, &got);
    samples_ = got;
    const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    renderer_ = name ? name : "";
    software_ = is_software_renderer(renderer_);
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
