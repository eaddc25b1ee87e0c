// clothsim-make-meshes DIR: writes the bundled meshes to DIR as OBJ files: the collider meshes
// (clothsim/mesh_shapes.hpp) and the cloth meshes (clothsim/cloth_mesh_shapes.hpp). They are made by the project,
// like the textures, and share the project's licence.
#include "clothsim/cloth_mesh_shapes.hpp"
#include "clothsim/mesh_file.hpp"
#include "clothsim/mesh_shapes.hpp"
#include "clothsim/scene.hpp"

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

int main(int argc, char** argv) {
    constexpr const char* kUsage = "usage: clothsim-make-meshes DIR\n  writes the bundled meshes (OBJ) into DIR, made if missing\n";
    // A flag is never taken for a folder to write into (a folder named "-x" is written as ./-x).
    if (argc == 2 && (std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h")) {
        std::fputs(kUsage, stdout);
        return 0;
    }
    if (argc != 2 || argv[1][0] == '-') {
        if (argc >= 2 && argv[1][0] == '-') std::fprintf(stderr, "clothsim-make-meshes: unknown option %s\n", argv[1]);
        std::fputs(kUsage, stderr);
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
        using clothsim::cloth_disc, clothsim::cloth_annulus, clothsim::cloth_cone_back;
        const std::string waist = std::to_string(clothsim::annulus_inner_count(0.275, 0.105, 0.025) - 1);
        const std::string collar = std::to_string(clothsim::cone_back_top_count(0.30, 0.025, 200.0) - 1);
        const std::string cloth[][2] = {
            {"cusick-disc-2k.obj", "A cloth: the Cusick specimen, a 30 cm disc of 25 rings (6 mm); the 18 cm support's rim is "
                                   "ring 15, vertices 631 .. 720 (from 0)."},
            {"cusick-disc-8k.obj", "A cloth: the Cusick specimen, a 30 cm disc of 50 rings (3 mm); the 18 cm support's rim is "
                                   "ring 30, vertices 2611 .. 2790 (from 0)."},
            {"circle-skirt.obj", "A cloth: a circle skirt, flat, an annulus from an elliptical waist 0.275 x 0.105 m out 0.45 m, "
                                 "2.5 cm edges; the waist is vertices 0 .. " + waist + " (from 0)."},
            {"cape.obj", "A cloth: a cape, the back 200 degrees of a cone from a 0.30 m ring down 0.85 m to a 0.62 m one, "
                         "2.5 cm edges; the top edge is vertices 0 .. " + collar + " (from 0)."},
            {"tabard.obj", "A cloth: a tabard, front and back panels 0.40 m wide sewn along the shoulder seam (y = z = 0) "
                           "either side of an 18 cm square neck, over a 0.14 m yoke; the front 0.75 m and the back 0.70 m "
                           "long, 2.5 cm edges; rows across from the back hem."},
        };
        const clothsim::TriangleMesh cloth_meshes[] = {cloth_disc(0.15, 25), cloth_disc(0.15, 50),
                                                       cloth_annulus(0.275, 0.105, 0.45, 0.025),
                                                       cloth_cone_back(0.30, 0.62, 0.85, 0.025, 200.0),
                                                       clothsim::cloth_tabard(clothsim::TabardPattern{})};
        for (std::size_t k = 0; k < std::size(cloth_meshes); ++k) {
            const std::filesystem::path path = dir / cloth[k][0];
            clothsim::write_mesh_file(cloth_meshes[k], path,
                                      cloth[k][1] + "\nMade by clothsim-make-meshes (src/core/scene/cloth_mesh_shapes.cpp); clothsim's licence.");
            std::printf("wrote %s (%zu vertices, %zu triangles)\n", path.c_str(), cloth_meshes[k].vertices().size(),
                        cloth_meshes[k].triangles().size());
        }
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
