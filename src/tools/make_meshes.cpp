// clothsim-make-meshes DIR: writes the bundled meshes (clothsim/mesh_shapes.hpp) to DIR as OBJ files. They are
// made by the project, like the textures, and share the project's licence (assets/meshes/README.md).
#include "clothsim/mesh_file.hpp"
#include "clothsim/mesh_shapes.hpp"
#include "clothsim/scene.hpp"

#include <cstdio>
#include <filesystem>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: clothsim-make-meshes DIR\n");
        return 2;
    }
    const std::filesystem::path dir(argv[1]);
    try {
        std::filesystem::create_directories(dir);
        const clothsim::TriangleMesh table = clothsim::round_table();
        clothsim::write_mesh_file(table, dir / "round-table.obj",
                                  "A round pedestal table: top radius 0.5 m, 0.76 m high, standing on y = 0.\n"
                                  "Made by clothsim-make-meshes (src/core/collision/mesh_shapes.cpp); clothsim's licence.");
        std::printf("wrote %s (%zu triangles)\n", (dir / "round-table.obj").c_str(), table.triangles().size());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "clothsim-make-meshes: %s\n", e.what());
        return 1;
    }
    return 0;
}
