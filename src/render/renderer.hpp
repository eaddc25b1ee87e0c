// The renderer: draws the cloth, the colliders and the ground with OpenGL 3.3 core. It only reads the
// simulation (positions, topology, settings) and owns every GL object it creates.
#pragma once

#include "gl_objects.hpp"
#include "meshes.hpp"
#include "shader.hpp"

#include "camera.hpp"
#include "clothsim/mass_spring.hpp"

#include <glm/mat4x4.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

namespace clothsim {

enum class SpringView { Off, ByKind, ByStrain };

// What the View section of the panel toggles. Not part of a scene: how to look, not what to simulate.
struct ViewSettings {
    bool wireframe = false;       // W: cloth as wires instead of shaded
    SpringView springs = SpringView::Off;
    float strain_range = 0.1f;    // |strain| mapped to full colour when springs are coloured by strain
    bool particles = false;
    bool highlight_pins = true;
    bool texture = true;
    bool shadows = true;
};

// A static mesh on the GPU: positions, normals, UVs and triangle indices.
class GpuMesh {
public:
    explicit GpuMesh(const MeshData& data, bool dynamic = false);
    void update_positions_normals(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals);
    void draw() const;

private:
    gl::VertexArray vao_;
    gl::Buffer positions_, normals_, uvs_, indices_;
    GLsizei index_count_ = 0;
};

struct RenderInput {
    const MassSpring& sim;
    const OrbitCamera& camera;
    glm::ivec2 framebuffer_px;
    glm::ivec4 viewport_px;  // x, y (from the bottom-left), width, height: the 3D view beside the panel
    const ViewSettings& view;
    std::optional<std::size_t> grabbed;
};

class Renderer {
public:
    // Loads the shaders and textures; throws gl::ShaderError or std::runtime_error naming the file.
    Renderer(const std::filesystem::path& shader_dir, const std::filesystem::path& texture_dir);

    // Must be called when the simulation is replaced or its topology changes (a rebuild, a reset, a scene
    // opened): re-creates the cloth's mesh and its CPU copy from `sim`, at once.
    void set_cloth(const MassSpring& sim);
    void draw(const RenderInput& input);

    // What the last draw() spent preparing the cloth: vertex normals and the upload of positions and
    // normals. Both are skipped (and `cloth_uploaded` is false) while the cloth has not moved since the last
    // upload (MassSpring::change_stamp).
    struct ClothTimings {
        float normals_ms = 0.0f;
        float upload_ms = 0.0f;
        bool cloth_uploaded = false;
        long long uploads = 0;  // since the renderer was made
        long long skipped = 0;
    };
    const ClothTimings& cloth_timings() const { return cloth_timings_; }

    // The cloth's positions as the renderer holds them (what the last draw showed): always one per particle
    // of the cloth last given to set_cloth or draw.
    std::span<const glm::vec3> cloth_positions() const { return positions_; }

private:
    void sync_cloth(const MassSpring& sim, bool rebuild);
    void draw_shadow_map(const RenderInput& input, const glm::mat4& light_view_projection);
    void draw_lit(const RenderInput& input, const glm::mat4& view_projection, const glm::mat4& light_view_projection);
    void draw_debug(const RenderInput& input, const glm::mat4& view_projection);
    // A collider's mesh (shapes/shape.hpp): a unit mesh, or a mesh collider's triangles, uploaded at its first
    // draw and dropped once a frame no longer draws it.
    const GpuMesh& mesh_of(const ShapeDrawing& d);

    gl::Shader lit_;
    gl::Shader shadow_;
    gl::Shader lines_;
    gl::Texture fabric_;
    gl::Texture crate_;
    gl::Texture shadow_depth_;
    gl::Framebuffer shadow_fbo_;
    int shadow_size_ = 2048;

    GpuMesh sphere_;
    GpuMesh cube_;
    GpuMesh cylinder_;
    GpuMesh ground_;
    struct ColliderMesh {
        const TriangleMesh* source;
        std::size_t triangles;
        GpuMesh mesh;
        bool drawn;  // in the frame being drawn
    };
    std::vector<ColliderMesh> collider_meshes_;
    // The cloth as drawn: the CPU copy (positions_, normals_) and the GPU mesh made from that copy. Only
    // sync_cloth writes them, all together, so the copy, the mesh and the stamp always describe one cloth.
    std::optional<GpuMesh> cloth_;
    std::vector<glm::vec3> positions_, normals_;
    std::vector<glm::vec3> surface_vertices_;  // a torn cloth's: positions_ and then its split vertices
    std::uint64_t synced_stamp_ = 0;  // the change_stamp of positions_ (0: none; stamps start at 1)
    std::uint64_t synced_topology_stamp_ = 0;  // the topology_stamp the mesh's triangles belong to
    ClothTimings cloth_timings_;
    glm::vec2 cloth_uv_scale_{1.0f};

    // Debug lines and points: position + colour per vertex, rebuilt each frame they are shown.
    gl::VertexArray debug_vao_;
    gl::Buffer debug_vbo_;
    struct DebugVertex {
        glm::vec3 position;
        glm::vec4 color;
    };
    std::vector<DebugVertex> debug_;
};

}  // namespace clothsim
