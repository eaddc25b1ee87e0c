#include "shader.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

#ifndef CLOTHSIM_DEFAULT_SHADER_DIR
#define CLOTHSIM_DEFAULT_SHADER_DIR "shaders"
#endif

namespace clothsim::gl {
namespace {

std::string read_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ShaderError("cannot read shader file '" + path.string() + "'");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::string info_log(GLuint object, bool program) {
    GLint length = 0;
    program ? glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length) : glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<std::size_t>(std::max(length, 1)));
    program ? glGetProgramInfoLog(object, length, nullptr, log.data())
            : glGetShaderInfoLog(object, length, nullptr, log.data());
    return std::string(log.data());
}

GLuint compile(GLenum stage, const std::filesystem::path& path) {
    const std::string source = read_file(path);
    const GLuint shader = glCreateShader(stage);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        const std::string log = annotate_log(info_log(shader, false), path.string());
        glDeleteShader(shader);
        throw ShaderError("shader " + path.string() + " failed to compile:\n" + log);
    }
    return shader;
}

}  // namespace

std::string annotate_log(const std::string& log, const std::string& file) {
    static const std::regex mesa(R"(\b0:(\d+)\((\d+)\))");  // Mesa: 0:12(5): error: ...
    static const std::regex nvidia(R"(\b0\((\d+)\))");      // NVIDIA: 0(12) : error ...
    std::string out = std::regex_replace(log, mesa, file + ":$1:$2");
    return std::regex_replace(out, nvidia, file + ":$1");
}

std::filesystem::path shader_directory() {
    if (const char* dir = std::getenv("CLOTHSIM_SHADERS"); dir && *dir) return dir;
    return CLOTHSIM_DEFAULT_SHADER_DIR;
}

Shader::Shader(const std::filesystem::path& vertex, const std::filesystem::path& fragment) {
    const GLuint vs = compile(GL_VERTEX_SHADER, vertex);
    GLuint fs = 0;
    try {
        fs = compile(GL_FRAGMENT_SHADER, fragment);
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    glAttachShader(program_.get(), vs);
    glAttachShader(program_.get(), fs);
    glLinkProgram(program_.get());
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = GL_FALSE;
    glGetProgramiv(program_.get(), GL_LINK_STATUS, &ok);
    if (!ok) {
        throw ShaderError("shaders " + vertex.string() + " + " + fragment.string() + " failed to link:\n" +
                          info_log(program_.get(), true));
    }
}

void Shader::set(const char* name, glm::vec3 v) const { glUniform3fv(location(name), 1, glm::value_ptr(v)); }
void Shader::set(const char* name, glm::vec4 v) const { glUniform4fv(location(name), 1, glm::value_ptr(v)); }
void Shader::set(const char* name, const glm::mat4& m) const {
    glUniformMatrix4fv(location(name), 1, GL_FALSE, glm::value_ptr(m));
}

}  // namespace clothsim::gl
