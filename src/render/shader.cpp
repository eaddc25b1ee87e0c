#include "shader.hpp"

#include "clothsim/data_dirs.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <fstream>
#include <cctype>
#include <sstream>
#include <vector>

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
    // Mesa writes "0:LINE(COL): error", NVIDIA "0(LINE) : error": source string 0 is our file.
    std::string out;
    std::size_t i = 0;
    auto digits = [&](std::size_t from) {
        std::size_t end = from;
        while (end < log.size() && std::isdigit(static_cast<unsigned char>(log[end]))) ++end;
        return end;
    };
    while (i < log.size()) {
        const bool at_start = i == 0 || !std::isalnum(static_cast<unsigned char>(log[i - 1]));
        if (at_start && log.compare(i, 2, "0:") == 0) {  // Mesa
            const std::size_t line_end = digits(i + 2);
            if (line_end > i + 2 && line_end < log.size() && log[line_end] == '(') {
                const std::size_t col_end = digits(line_end + 1);
                if (col_end > line_end + 1 && col_end < log.size() && log[col_end] == ')') {
                    out += file + ":" + log.substr(i + 2, line_end - i - 2) + ":" +
                           log.substr(line_end + 1, col_end - line_end - 1);
                    i = col_end + 1;
                    continue;
                }
            }
        }
        if (at_start && log.compare(i, 2, "0(") == 0) {  // NVIDIA
            const std::size_t line_end = digits(i + 2);
            if (line_end > i + 2 && line_end < log.size() && log[line_end] == ')') {
                out += file + ":" + log.substr(i + 2, line_end - i - 2);
                i = line_end + 1;
                continue;
            }
        }
        out += log[i++];
    }
    return out;
}

std::filesystem::path shader_directory() {
    return data_directory("CLOTHSIM_SHADERS", "shaders");
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
