// The OBJ export of a torn cloth (export.hpp) checked against its split surface (cloth_surface.hpp): shared by
// the tearing and the cloth-surface tests.
#pragma once

#include "clothsim/cloth_surface.hpp"
#include "clothsim/export.hpp"
#include "clothsim/mass_spring.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace clothsim::test {

// Writes `sim`'s OBJ and checks it is the split surface: its vertices, a texture coordinate for each (faces name
// vertex i with texture coordinate i), and its triangles.
inline void check_obj_is_the_split_surface(const MassSpring& sim) {
    const std::string path =
        (std::filesystem::temp_directory_path() / ("clothsim-torn-" + std::to_string(::getpid()) + ".obj")).string();
    std::string error;
    REQUIRE(write_obj(sim, path, error));
    const ClothSurface& surface = sim.surface();
    REQUIRE(surface.split());
    std::ifstream in(path);
    std::size_t faces = 0, vertices = 0, uvs = 0;
    bool indices_in_range = true;
    for (std::string line; std::getline(in, line);) {
        vertices += line.rfind("v ", 0) == 0 ? 1 : 0;
        uvs += line.rfind("vt ", 0) == 0 ? 1 : 0;
        if (line.rfind("f ", 0) != 0) continue;
        ++faces;
        std::istringstream f(line.substr(2));
        for (std::string corner; f >> corner;) {
            const std::size_t slash = corner.find('/');
            REQUIRE(slash != std::string::npos);
            const std::size_t index = std::stoul(corner.substr(0, slash)), texture = std::stoul(corner.substr(slash + 1));
            indices_in_range = indices_in_range && index >= 1 && index <= surface.vertex_count() && texture == index;
        }
    }
    in.close();
    std::filesystem::remove(path);
    CHECK(faces == surface.triangles.size());
    CHECK(vertices == surface.vertex_count());
    CHECK(uvs == surface.vertex_count());
    CHECK(indices_in_range);
}

}  // namespace clothsim::test
