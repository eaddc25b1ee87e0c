// Shader compiler logs are rewritten to name the file and line (no GL context needed).
#include "shader.hpp"

#include <catch2/catch.hpp>

TEST_CASE("shader log: Mesa and NVIDIA locations become file:line", "[shader]") {
    using clothsim::gl::annotate_log;
    CHECK(annotate_log("0:12(5): error: syntax error, unexpected ';'\n", "shaders/lit.frag") ==
          "shaders/lit.frag:12:5: error: syntax error, unexpected ';'\n");
    CHECK(annotate_log("0(7) : error C0000: syntax error\n", "a.vert") == "a.vert:7 : error C0000: syntax error\n");
    CHECK(annotate_log("0:3(1): warning\n0:40(22): error\n", "f") == "f:3:1: warning\nf:40:22: error\n");
    // Numbers that are not locations stay as they are.
    CHECK(annotate_log("version 330 expected, 10:2 seen", "f") == "version 330 expected, 10:2 seen");
    CHECK(annotate_log("", "f").empty());
}
