#include "core/mesh.hpp"

namespace lodstream {

void compute_smooth_normals(Mesh& mesh) {
  mesh.normals.assign(mesh.positions.size(), glm::vec3(0.0f));
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* v = &mesh.indices[3 * t];
    // The unnormalized cross product weights each face by its area.
    glm::vec3 n =
        glm::cross(mesh.positions[v[1]] - mesh.positions[v[0]], mesh.positions[v[2]] - mesh.positions[v[0]]);
    for (int k = 0; k < 3; ++k) mesh.normals[v[k]] += n;
  }
  for (auto& n : mesh.normals) {
    float len = glm::length(n);
    n = len > 0.0f ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
}

float triangle_double_area(const Mesh& mesh, size_t t) {
  const uint32_t* v = &mesh.indices[3 * t];
  return glm::length(
      glm::cross(mesh.positions[v[1]] - mesh.positions[v[0]], mesh.positions[v[2]] - mesh.positions[v[0]]));
}

}  // namespace lodstream
