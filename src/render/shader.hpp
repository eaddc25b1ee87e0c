// GLSL programs loaded from shaders/. Compile and link errors are reported with the file and line the
// driver names, e.g. "shaders/lit.frag:12: error: 'nrm' undeclared".
#pragma once

#include "gl_objects.hpp"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace clothsim::gl {

class ShaderError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

class Shader {
public:
    // Compiles and links `vertex` and `fragment` (paths). Throws ShaderError naming file and line.
    Shader(const std::filesystem::path& vertex, const std::filesystem::path& fragment);

    void use() const { glUseProgram(program_.get()); }
    GLint location(const char* name) const { return glGetUniformLocation(program_.get(), name); }
    void set(const char* name, int v) const { glUniform1i(location(name), v); }
    void set(const char* name, float v) const { glUniform1f(location(name), v); }
    void set(const char* name, glm::vec3 v) const;
    void set(const char* name, glm::vec4 v) const;
    void set(const char* name, const glm::mat4& m) const;

private:
    Program program_;
};

// Rewrites a driver's info log so each "0:LINE(COL)" or "0:LINE:" refers to "FILE:LINE" (Mesa and NVIDIA
// both name the source string 0). Exposed for the tests.
std::string annotate_log(const std::string& log, const std::string& file);

std::filesystem::path shader_directory();  // $CLOTHSIM_SHADERS, else share/clothsim/shaders (data_dirs.hpp)

}  // namespace clothsim::gl
