// clothsim-make-meshes DIR: writes the bundled meshes (clothsim/mesh_shapes.hpp) to DIR as OBJ files. They are
// made by the project, like the textures, and share the project's licence (assets/meshes/README.md).
#include "clothsim/mesh_file.hpp"
#include "clothsim/mesh_shapes.hpp"
#include "clothsim/scene.hpp"

#include <cstdio>
#include <filesystem>
#include <string>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: clothsim-make-meshes DIR\n");
        return 2;
    }
    const std::filesystem::path dir(argv[1]);
    try {
        std::filesystem::create_directories(dir);
        struct Made {
            const char* file;
            clothsim::TriangleMesh mesh;
            const char* what;
        };
        const Made made[] = {
            {"round-table.obj", clothsim::round_table(), "A round pedestal table: top radius 0.5 m, 0.76 m high, standing on y = 0."},
            {"mannequin.obj", clothsim::mannequin(),
             "A dress-form mannequin on a stand, arms at its sides: 1.61 m high, 0.56 m across, standing on y = 0."},
            {"chair.obj", clothsim::chair(), "A chair: seat 0.47 m high and 0.44 m square, backrest to 0.97 m, standing on y = 0."},
        };
        for (const Made& m : made) {
            clothsim::write_mesh_file(m.mesh, dir / m.file,
                                      std::string(m.what) +
                                          "\nMade by clothsim-make-meshes (src/core/collision/mesh_shapes.cpp); clothsim's licence.");
            std::printf("wrote %s (%zu triangles)\n", (dir / m.file).c_str(), m.mesh.triangles().size());
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "clothsim-make-meshes: %s\n", e.what());
        return 1;
    }
    return 0;
}
