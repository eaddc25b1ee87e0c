#include "renderer.hpp"

#include "clothsim/normals.hpp"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <stb_image.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace clothsim {
namespace {

const glm::vec3 kLightDirection = glm::normalize(glm::vec3(0.45f, 1.0f, 0.35f));  // toward the light

gl::Texture load_texture(const std::filesystem::path& path) {
    int w = 0, h = 0, channels = 0;
    stbi_set_flip_vertically_on_load(1);
    unsigned char* pixels = stbi_load(path.string().c_str(), &w, &h, &channels, 4);
    if (!pixels) {
        throw std::runtime_error("cannot load texture '" + path.string() + "': " + stbi_failure_reason());
    }
    gl::Texture texture;
    glBindTexture(GL_TEXTURE_2D, texture.get());
    glTexImage2D(GL_TEXTURE_2D, 0, GL_SRGB8_ALPHA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, pixels);
    stbi_image_free(pixels);
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    return texture;
}

template <class T>
void upload(const gl::Buffer& buffer, GLenum target, const std::vector<T>& data, GLenum usage) {
    glBindBuffer(target, buffer.get());
    glBufferData(target, static_cast<GLsizeiptr>(data.size() * sizeof(T)), data.data(), usage);
}

void attribute(GLuint index, const gl::Buffer& buffer, int components) {
    glBindBuffer(GL_ARRAY_BUFFER, buffer.get());
    glEnableVertexAttribArray(index);
    glVertexAttribPointer(index, components, GL_FLOAT, GL_FALSE, 0, nullptr);
}

// Blue (compressed) through white (rest length) to red (stretched).
glm::vec4 strain_color(float strain, float range) {
    const float s = std::clamp(strain / std::max(range, 1e-6f), -1.0f, 1.0f);
    return s >= 0.0f ? glm::vec4(1.0f, 1.0f - s, 1.0f - s, 1.0f) : glm::vec4(1.0f + s, 1.0f + s, 1.0f, 1.0f);
}

glm::vec4 kind_color(SpringKind kind) {
    switch (kind) {
        case SpringKind::Structural: return {1.0f, 0.85f, 0.2f, 1.0f};
        case SpringKind::Shear: return {0.2f, 0.85f, 1.0f, 1.0f};
        case SpringKind::Bending: return {1.0f, 0.35f, 0.9f, 1.0f};
    }
    return glm::vec4(1.0f);
}

// Where a collider's unit mesh (meshes.hpp) stands: scaled, then moved (shape.hpp's ShapeDrawing).
glm::mat4 model_of(const ShapeDrawing& d) {
    glm::mat4 model = glm::translate(glm::mat4(1.0f), d.center);
    // Turned about x, then y, then z (shapes/mesh.hpp: R = Rz Ry Rx).
    model = glm::rotate(model, glm::radians(d.rotation.z), glm::vec3(0.0f, 0.0f, 1.0f));
    model = glm::rotate(model, glm::radians(d.rotation.y), glm::vec3(0.0f, 1.0f, 0.0f));
    model = glm::rotate(model, glm::radians(d.rotation.x), glm::vec3(1.0f, 0.0f, 0.0f));
    return glm::scale(model, d.scale);
}

}  // namespace

GpuMesh::GpuMesh(const MeshData& data, bool dynamic) : index_count_(static_cast<GLsizei>(data.indices.size())) {
    glBindVertexArray(vao_.get());
    const GLenum usage = dynamic ? GL_DYNAMIC_DRAW : GL_STATIC_DRAW;
    upload(positions_, GL_ARRAY_BUFFER, data.positions, usage);
    attribute(0, positions_, 3);
    upload(normals_, GL_ARRAY_BUFFER, data.normals, usage);
    attribute(1, normals_, 3);
    upload(uvs_, GL_ARRAY_BUFFER, data.uvs, GL_STATIC_DRAW);
    attribute(2, uvs_, 2);
    upload(indices_, GL_ELEMENT_ARRAY_BUFFER, data.indices, GL_STATIC_DRAW);
    glBindVertexArray(0);
}

void GpuMesh::update_positions_normals(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals) {
    glBindBuffer(GL_ARRAY_BUFFER, positions_.get());
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(positions.size() * sizeof(glm::vec3)), positions.data());
    glBindBuffer(GL_ARRAY_BUFFER, normals_.get());
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(normals.size() * sizeof(glm::vec3)), normals.data());
}

void GpuMesh::draw() const {
    glBindVertexArray(vao_.get());
    glDrawElements(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr);
}

Renderer::Renderer(const std::filesystem::path& shader_dir, const std::filesystem::path& texture_dir)
    : lit_(shader_dir / "lit.vert", shader_dir / "lit.frag"),
      shadow_(shader_dir / "shadow.vert", shader_dir / "shadow.frag"),
      lines_(shader_dir / "lines.vert", shader_dir / "lines.frag"),
      fabric_(load_texture(texture_dir / "fabric.png")),
      crate_(load_texture(texture_dir / "crate.png")),
      sphere_(make_uv_sphere(32, 64)),
      cube_(make_cube()),
      cylinder_(make_cylinder(96)),
      ground_(make_ground(50.0f)) {
    glBindTexture(GL_TEXTURE_2D, shadow_depth_.get());
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, shadow_size_, shadow_size_, 0, GL_DEPTH_COMPONENT, GL_FLOAT,
                 nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo_.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_depth_.get(), 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        throw std::runtime_error("the shadow-map framebuffer is incomplete on this OpenGL driver");
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    glBindVertexArray(debug_vao_.get());
    glBindBuffer(GL_ARRAY_BUFFER, debug_vbo_.get());
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(DebugVertex), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(DebugVertex),
                          reinterpret_cast<const void*>(offsetof(DebugVertex, color)));
    glBindVertexArray(0);
}

void Renderer::set_cloth(const MassSpring& sim) { sync_cloth(sim, true); }

// Brings the CPU copy and the GPU mesh to `sim`'s positions. A rebuild (or a cloth of another particle
// count) makes the mesh anew from the copy; otherwise the copy and the mesh's vertex buffers are refreshed
// when the cloth moved since the last sync (MassSpring::change_stamp, unique across simulations).
void Renderer::sync_cloth(const MassSpring& sim, bool rebuild) {
    using Clock = std::chrono::steady_clock;
    cloth_timings_.normals_ms = cloth_timings_.upload_ms = 0.0f;
    cloth_timings_.cloth_uploaded = false;
    rebuild = rebuild || !cloth_ || positions_.size() != sim.particle_count() ||
              sim.topology_stamp() != synced_topology_stamp_;  // a tear changed the triangles
    if (!rebuild && sim.change_stamp() == synced_stamp_) {
        ++cloth_timings_.skipped;  // nothing moved (a sleeping or paused cloth): the GPU has these positions
        return;
    }
    const auto start = Clock::now();
    const Topology& t = sim.topology();
    sim.positions(positions_);
    // A torn cloth is drawn split along its tears (cloth_surface.hpp): the split vertices follow the particles.
    const ClothSurface& surface = sim.surface();
    if (surface.split()) {
        surface_vertices_ = positions_;
        place_split_vertices(surface, surface_vertices_);
        split_surface_normals(surface, surface_vertices_, normals_);
    } else {
        surface_vertices_.clear();
        compute_vertex_normals(t, sim.state().position, normals_);
    }
    const std::vector<glm::vec3>& vertices = surface.split() ? surface_vertices_ : positions_;
    const auto normals_done = Clock::now();
    if (rebuild) {
        MeshData data;
        data.positions = vertices;
        data.normals = normals_;
        if (t.mesh) {
            data.uvs = t.uv;  // in metres
        } else {
            for (int r = 0; r < t.rows; ++r) {
                for (int c = 0; c < t.cols; ++c) data.uvs.push_back(grid_uv(t, glm::vec2(float(c), float(r))));
            }
        }
        for (const glm::vec2& place : surface.split_place) data.uvs.push_back(t.mesh ? place : grid_uv(t, place));
        for (const auto& tri : surface.split() ? surface.triangles : t.triangles) {
            data.indices.insert(data.indices.end(), tri.begin(), tri.end());
        }
        cloth_.emplace(data, true);
        // The weave repeats every 12 cm of cloth, whatever the grid's resolution or aspect.
        glm::vec2 extent(0.0f);
        if (t.mesh) {
            extent = glm::vec2(1.0f);  // the mesh's coordinates are metres already
        } else if (!positions_.empty()) {
            extent = {glm::length(positions_[t.index(0, t.cols - 1)] - positions_[0]),
                      glm::length(positions_[t.index(t.rows - 1, 0)] - positions_[0])};
        }
        cloth_uv_scale_ = glm::max(extent / 0.12f, glm::vec2(1.0f));
    } else {
        cloth_->update_positions_normals(vertices, normals_);
    }
    synced_stamp_ = sim.change_stamp();
    synced_topology_stamp_ = sim.topology_stamp();
    cloth_timings_.normals_ms = std::chrono::duration<float, std::milli>(normals_done - start).count();
    cloth_timings_.upload_ms = std::chrono::duration<float, std::milli>(Clock::now() - normals_done).count();
    cloth_timings_.cloth_uploaded = true;
    ++cloth_timings_.uploads;
}

void Renderer::draw(const RenderInput& input) {
    sync_cloth(input.sim, false);
    const glm::ivec4 vp = input.viewport_px;
    const float aspect = float(vp.z) / float(std::max(vp.w, 1));
    const glm::mat4 view_projection = input.camera.projection(aspect) * input.camera.view();

    glm::vec3 lo, hi;
    scene_bounds(input.sim, lo, hi);
    const glm::vec3 center = 0.5f * (lo + hi);
    const float radius = std::max(0.5f * glm::length(hi - lo), 0.5f) * 1.2f;
    const glm::mat4 light_view =
        glm::lookAt(center + kLightDirection * (2.0f * radius), center, glm::vec3(0.0f, 1.0f, 0.0f));
    const glm::mat4 light_view_projection =
        glm::ortho(-radius, radius, -radius, radius, 0.01f, 4.0f * radius) * light_view;

    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    if (input.view.shadows) draw_shadow_map(input, light_view_projection);

    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, input.framebuffer_px.x, input.framebuffer_px.y);
    glEnable(GL_FRAMEBUFFER_SRGB);
    glClearColor(0.42f, 0.47f, 0.54f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glViewport(vp.x, vp.y, vp.z, vp.w);
    draw_lit(input, view_projection, light_view_projection);
    glDisable(GL_FRAMEBUFFER_SRGB);
    draw_debug(input, view_projection);
    glBindVertexArray(0);
}

void Renderer::draw_shadow_map(const RenderInput& input, const glm::mat4& light_view_projection) {
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo_.get());
    glViewport(0, 0, shadow_size_, shadow_size_);
    glClear(GL_DEPTH_BUFFER_BIT);
    shadow_.use();
    shadow_.set("u_light_view_projection", light_view_projection);
    shadow_.set("u_model", glm::mat4(1.0f));
    if (!input.sim.topology().triangles.empty() || input.sim.surface().split()) cloth_->draw();
    for (const Collider& collider : input.sim.colliders()) {
        const ShapeDrawing d = drawing(collider);
        if (!collider.enabled || d.mesh == UnitMesh::Plane) continue;  // the floor casts no shadow
        shadow_.set("u_model", model_of(d));
        mesh_of(d).draw();
    }
}

const GpuMesh& Renderer::mesh_of(const ShapeDrawing& d) {
    switch (d.mesh) {
        case UnitMesh::Sphere: return sphere_;
        case UnitMesh::Cube: return cube_;
        case UnitMesh::Cylinder: return cylinder_;
        case UnitMesh::Mesh: {
            if (!d.triangles) break;
            const std::size_t count = d.triangles->triangles().size();
            for (ColliderMesh& m : collider_meshes_) {
                if (m.source == d.triangles && m.triangles == count) {
                    m.drawn = true;
                    return m.mesh;
                }
            }
            collider_meshes_.push_back({d.triangles, count, GpuMesh(make_collider_mesh(*d.triangles)), true});
            return collider_meshes_.back().mesh;
        }
        case UnitMesh::Plane: break;
    }
    return ground_;
}

void Renderer::draw_lit(const RenderInput& input, const glm::mat4& view_projection,
                        const glm::mat4& light_view_projection) {
    lit_.use();
    lit_.set("u_view_projection", view_projection);
    lit_.set("u_light_view_projection", light_view_projection);
    lit_.set("u_light_direction", kLightDirection);
    lit_.set("u_camera", input.camera.eye());
    lit_.set("u_use_shadow", input.view.shadows ? 1 : 0);
    lit_.set("u_texture", 0);
    lit_.set("u_shadow_map", 1);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, shadow_depth_.get());
    glActiveTexture(GL_TEXTURE0);

    auto material = [&](glm::vec4 color, const gl::Texture* texture, glm::vec2 uv_scale, float specular, float shininess) {
        lit_.set("u_color", color);
        lit_.set("u_use_texture", texture ? 1 : 0);
        if (texture) glBindTexture(GL_TEXTURE_2D, texture->get());
        glUniform2f(lit_.location("u_uv_scale"), uv_scale.x, uv_scale.y);
        lit_.set("u_specular", specular);
        lit_.set("u_shininess", shininess);
        lit_.set("u_grid", 0);
    };

    // The floor: each plane that collides, opaque; a faint grid at the first plane's height (or at 0) when none
    // does.
    const std::vector<Collider>& shapes = input.sim.colliders();
    std::vector<float> floors;
    float faint = 0.0f;
    bool faint_set = false;
    for (const Collider& collider : shapes) {
        const ShapeDrawing d = drawing(collider);
        if (d.mesh != UnitMesh::Plane) continue;
        if (collider.enabled) floors.push_back(d.center.y);
        if (!faint_set) faint = d.center.y, faint_set = true;
    }
    const bool solid_floor = !floors.empty();
    if (!solid_floor) floors.push_back(faint);
    material(solid_floor ? glm::vec4(0.55f, 0.58f, 0.55f, 1.0f) : glm::vec4(0.55f, 0.58f, 0.55f, 0.35f), nullptr,
             glm::vec2(1.0f), 0.05f, 16.0f);
    lit_.set("u_grid", 1);
    if (!solid_floor) {
        glEnable(GL_BLEND);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        glDepthMask(GL_FALSE);
    }
    for (float height : floors) {
        lit_.set("u_model", glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, height, 0.0f)));
        ground_.draw();
    }
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);

    // The solid shapes, each kind in its own look: a blue sphere, a crate, a green cylinder.
    for (const Collider& collider : shapes) {
        const ShapeDrawing d = drawing(collider);
        if (!collider.enabled || d.mesh == UnitMesh::Plane) continue;
        switch (d.mesh) {
            case UnitMesh::Sphere: material({0.25f, 0.45f, 0.85f, 1.0f}, nullptr, glm::vec2(1.0f), 0.5f, 48.0f); break;
            case UnitMesh::Cube: material(glm::vec4(1.0f), &crate_, glm::vec2(1.0f), 0.35f, 32.0f); break;
            case UnitMesh::Cylinder: material({0.30f, 0.62f, 0.38f, 1.0f}, nullptr, glm::vec2(1.0f), 0.45f, 40.0f); break;
            case UnitMesh::Mesh: material({0.72f, 0.60f, 0.46f, 1.0f}, nullptr, glm::vec2(1.0f), 0.3f, 32.0f); break;
            case UnitMesh::Plane: break;
        }
        lit_.set("u_model", model_of(d));
        mesh_of(d).draw();
    }
    // A mesh no collider drew this frame (removed, or its scene replaced) leaves the GPU.
    std::erase_if(collider_meshes_, [](const ColliderMesh& m) { return !m.drawn; });
    for (ColliderMesh& m : collider_meshes_) m.drawn = false;
    if (!input.view.wireframe && (!input.sim.topology().triangles.empty() || input.sim.surface().split())) {
        material(input.view.texture ? glm::vec4(1.0f) : glm::vec4(0.80f, 0.36f, 0.26f, 1.0f),
                 input.view.texture ? &fabric_ : nullptr, cloth_uv_scale_, 0.08f, 12.0f);
        lit_.set("u_model", glm::mat4(1.0f));
        cloth_->draw();
    }
}

void Renderer::draw_debug(const RenderInput& input, const glm::mat4& view_projection) {
    const MassSpring& sim = input.sim;
    const ViewSettings& view = input.view;
    // sync_cloth ran this frame, so the copy has one position per particle of `sim`; every index below
    // (triangles, springs, pins, the grab) is a particle of `sim`.
    const std::span<const glm::vec3> positions = positions_;
    if (positions.size() != sim.particle_count()) return;
    lines_.use();
    lines_.set("u_view_projection", view_projection);
    lines_.set("u_round_points", 0);
    lines_.set("u_point_size", 1.0f);
    glBindVertexArray(debug_vao_.get());
    glBindBuffer(GL_ARRAY_BUFFER, debug_vbo_.get());
    auto flush = [&](GLenum mode) {
        if (debug_.empty()) return;
        glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(debug_.size() * sizeof(DebugVertex)), debug_.data(),
                     GL_STREAM_DRAW);
        glDrawArrays(mode, 0, static_cast<GLsizei>(debug_.size()));
        debug_.clear();
    };

    if (view.wireframe) {
        const glm::vec4 wire(0.95f, 0.55f, 0.35f, 1.0f);
        const ClothSurface& surface = sim.surface();
        const bool split = surface.split() && surface_vertices_.size() == surface.vertex_count();
        const std::span<const glm::vec3> vertices = split ? std::span<const glm::vec3>(surface_vertices_) : positions;
        for (const auto& t : split ? surface.triangles : sim.topology().triangles) {
            for (int e = 0; e < 3; ++e) {
                debug_.push_back({vertices[t[e]], wire});
                debug_.push_back({vertices[t[(e + 1) % 3]], wire});
            }
        }
        flush(GL_LINES);
    }
    if (view.springs != SpringView::Off) {
        for (const Spring& s : sim.topology().springs) {
            const glm::vec3 a = positions[s.a], b = positions[s.b];
            glm::vec4 color = kind_color(s.kind);
            if (view.springs == SpringView::ByStrain) {
                const float strain = s.rest_length > 0.0f ? glm::length(b - a) / s.rest_length - 1.0f : 0.0f;
                color = strain_color(strain, view.strain_range);
            }
            debug_.push_back({a, color});
            debug_.push_back({b, color});
        }
        flush(GL_LINES);
    }
    glEnable(GL_PROGRAM_POINT_SIZE);
    lines_.set("u_round_points", 1);
    // Points are drawn over the cloth so a pin or the grabbed particle is never hidden behind it.
    glDisable(GL_DEPTH_TEST);
    if (view.particles) {
        lines_.set("u_point_size", 4.0f);
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            if (sim.state().pinned[i] != kAbsent) debug_.push_back({positions[i], {0.1f, 0.1f, 0.1f, 1.0f}});
        }
        flush(GL_POINTS);
    }
    if (view.highlight_pins) {
        lines_.set("u_point_size", 9.0f);
        for (std::size_t i = 0; i < sim.particle_count(); ++i) {
            if (sim.state().pinned[i] == kPinned && i != input.grabbed) debug_.push_back({positions[i], {0.9f, 0.1f, 0.1f, 1.0f}});
        }
        flush(GL_POINTS);
        // A soft clip's particles, held but free to move: orange and smaller.
        lines_.set("u_point_size", 7.0f);
        for (const SoftClipSpring& hold : sim.topology().clip_springs) {
            if (sim.state().pinned[hold.particle] == 0 && hold.particle != input.grabbed) {
                debug_.push_back({positions[hold.particle], {1.0f, 0.6f, 0.0f, 1.0f}});
            }
        }
        flush(GL_POINTS);
    }
    if (input.grabbed && *input.grabbed < positions.size()) {
        lines_.set("u_point_size", 12.0f);
        debug_.push_back({positions[*input.grabbed], {1.0f, 0.9f, 0.1f, 1.0f}});
        flush(GL_POINTS);
    }
    glEnable(GL_DEPTH_TEST);
}

}  // namespace clothsim
