// data_directory: the folder an environment variable names, else the built-in one.
#include "clothsim/data_dirs.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>

TEST_CASE("data_directory: the variable when it is set and not empty, else the built-in folder", "[data_dirs]") {
    const char* name = "CLOTHSIM_TEST_DATA_DIRECTORY";
    ::unsetenv(name);
    CHECK(clothsim::data_directory(name, "built/in") == "built/in");
    ::setenv(name, "", 1);
    CHECK(clothsim::data_directory(name, "built/in") == "built/in");
    ::setenv(name, "/somewhere/else", 1);
    CHECK(clothsim::data_directory(name, "built/in") == "/somewhere/else");
    ::unsetenv(name);
}
