#include "clothsim/normals.hpp"

#include <glm/geometric.hpp>

namespace clothsim {

void compute_vertex_normals(const Topology& topology, const DVec3Array& position, std::vector<glm::vec3>& normals) {
    normals.assign(position.size(), glm::vec3(0.0f));
    for (const auto& t : topology.triangles) {
        // Edges in double, rounded to float: what is drawn needs no more.
        const glm::dvec3 a = position.get(t[0]);
        const glm::vec3 n = glm::cross(glm::vec3(position.get(t[1]) - a), glm::vec3(position.get(t[2]) - a));
        normals[t[0]] += n;
        normals[t[1]] += n;
        normals[t[2]] += n;
    }
    for (glm::vec3& n : normals) {
        const float length = glm::length(n);
        n = length > 1e-20f ? n / length : glm::vec3(0.0f, 1.0f, 0.0f);
    }
}

}  // namespace clothsim
