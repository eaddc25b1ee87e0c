#include "meshes.hpp"

#include "clothsim/triangle_mesh.hpp"

#include <glm/geometric.hpp>

#include <cmath>
#include <numbers>

namespace clothsim {

MeshData make_uv_sphere(int stacks, int slices) {
    MeshData m;
    const float pi = std::numbers::pi_v<float>;
    for (int i = 0; i <= stacks; ++i) {
        const float theta = pi * static_cast<float>(i) / static_cast<float>(stacks);  // from +y down
        for (int j = 0; j <= slices; ++j) {
            const float phi = 2.0f * pi * static_cast<float>(j) / static_cast<float>(slices);
            const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
            m.positions.push_back(n);
            m.normals.push_back(n);
            m.uvs.emplace_back(static_cast<float>(j) / static_cast<float>(slices),
                               1.0f - static_cast<float>(i) / static_cast<float>(stacks));
        }
    }
    const auto row = static_cast<std::uint32_t>(slices + 1);
    for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(stacks); ++i) {
        for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(slices); ++j) {
            const std::uint32_t a = i * row + j, b = a + row;
            m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
        }
    }
    return m;
}

MeshData make_cube() {
    MeshData m;
    // Each face: normal n and two in-face axes u, v with u x v = n.
    const glm::vec3 faces[6][3] = {
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    for (const auto& f : faces) {
        const auto base = static_cast<std::uint32_t>(m.positions.size());
        const glm::vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        for (const glm::vec2& c : corners) {
            m.positions.push_back(0.5f * f[0] + (c.x - 0.5f) * f[1] + (c.y - 0.5f) * f[2]);
            m.normals.push_back(f[0]);
            m.uvs.push_back(c);
        }
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    return m;
}

MeshData make_cylinder(int slices) {
    MeshData m;
    const float pi = std::numbers::pi_v<float>;
    // phi runs from +x toward -z, as the sphere's longitudes do: with the top ring first, (a, b, a + 1) is
    // counter-clockwise seen from outside.
    auto ring = [&](int j) {
        const float phi = 2.0f * pi * static_cast<float>(j) / static_cast<float>(slices);
        return glm::vec3(std::cos(phi), 0.0f, -std::sin(phi));
    };
    // Side: a top and a bottom vertex per slice edge (the seam is doubled for the UVs).
    for (int j = 0; j <= slices; ++j) {
        const glm::vec3 n = ring(j);
        const float u = static_cast<float>(j) / static_cast<float>(slices);
        for (float y : {0.5f, -0.5f}) {
            m.positions.push_back(n + glm::vec3(0.0f, y, 0.0f));
            m.normals.push_back(n);
            m.uvs.emplace_back(u, y + 0.5f);
        }
    }
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(slices); ++j) {
        const std::uint32_t a = 2 * j, b = a + 1;  // top and bottom of edge j; edge j + 1's are a + 2, b + 2
        m.indices.insert(m.indices.end(), {a, b, a + 2, a + 2, b, b + 2});
    }
    // Caps: a centre and a ring each, facing +y (top) and -y (bottom).
    for (float y : {0.5f, -0.5f}) {
        const glm::vec3 normal(0.0f, y > 0.0f ? 1.0f : -1.0f, 0.0f);
        const auto centre = static_cast<std::uint32_t>(m.positions.size());
        m.positions.emplace_back(0.0f, y, 0.0f);
        m.normals.push_back(normal);
        m.uvs.emplace_back(0.5f, 0.5f);
        for (int j = 0; j < slices; ++j) {
            const glm::vec3 n = ring(j);
            m.positions.push_back(n + glm::vec3(0.0f, y, 0.0f));
            m.normals.push_back(normal);
            m.uvs.emplace_back(0.5f + 0.5f * n.x, 0.5f - 0.5f * n.z);
        }
        for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(slices); ++j) {
            const std::uint32_t k = centre + 1 + j, next = centre + 1 + (j + 1) % static_cast<std::uint32_t>(slices);
            // Counter-clockwise seen from above for the top, from below for the bottom.
            if (y > 0.0f) m.indices.insert(m.indices.end(), {centre, k, next});
            else m.indices.insert(m.indices.end(), {centre, next, k});
        }
    }
    return m;
}

MeshData make_ground(float half_size) {
    MeshData m;
    const glm::vec2 corners[4] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
    for (const glm::vec2& c : corners) {
        m.positions.emplace_back(c.x * half_size, 0.0f, c.y * half_size);
        m.normals.emplace_back(0.0f, 1.0f, 0.0f);
        m.uvs.emplace_back(c * half_size);
    }
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

MeshData make_collider_mesh(const TriangleMesh& mesh) {
    MeshData m;
    const std::size_t n = mesh.triangles().size();
    m.positions.reserve(3 * n);
    m.normals.reserve(3 * n);
    m.uvs.assign(3 * n, glm::vec2(0.0f));
    m.indices.reserve(3 * n);
    const double kSmooth = 0.8660254037844387;  // cos 30 degrees
    for (std::size_t t = 0; t < n; ++t) {
        const glm::dvec3 face = mesh.face_normals()[t];
        for (std::uint32_t v : mesh.triangles()[t]) {
            const glm::dvec3 smooth = mesh.vertex_normals()[v];
            m.indices.push_back(static_cast<std::uint32_t>(m.positions.size()));
            m.positions.push_back(glm::vec3(mesh.vertices()[v]));
            m.normals.push_back(glm::vec3(glm::dot(smooth, face) > kSmooth ? smooth : face));
        }
    }
    return m;
}

}  // namespace clothsim
