#include "hierarchy/clusterize.hpp"

#include <meshoptimizer.h>

namespace lodstream::hierarchy {

std::vector<ClusterPart> clusterize(const Mesh& mesh, size_t max_vertices, size_t max_triangles) {
  std::vector<ClusterPart> parts;
  if (mesh.indices.empty()) return parts;
  std::vector<uint32_t> sorted(mesh.indices.size());
  meshopt_spatialSortTriangles(sorted.data(), mesh.indices.data(), mesh.indices.size(), &mesh.positions[0].x,
                               mesh.positions.size(), sizeof(glm::vec3));
  const size_t bound = meshopt_buildMeshletsBound(sorted.size(), max_vertices, max_triangles);
  std::vector<meshopt_Meshlet> meshlets(bound);
  std::vector<unsigned int> meshlet_vertices(bound * max_vertices);
  std::vector<unsigned char> meshlet_triangles(bound * max_triangles * 3);
  // cone_weight 0: clusters are grouped for simplification, not for backface culling.
  const size_t count = meshopt_buildMeshlets(
      meshlets.data(), meshlet_vertices.data(), meshlet_triangles.data(), sorted.data(), sorted.size(),
      &mesh.positions[0].x, mesh.positions.size(), sizeof(glm::vec3), max_vertices, max_triangles, 0.0f);
  parts.resize(count);
  for (size_t m = 0; m < count; ++m) {
    const meshopt_Meshlet& ml = meshlets[m];
    ClusterPart& part = parts[m];
    part.vertices.assign(meshlet_vertices.begin() + ml.vertex_offset,
                         meshlet_vertices.begin() + ml.vertex_offset + ml.vertex_count);
    part.indices.assign(meshlet_triangles.begin() + ml.triangle_offset,
                        meshlet_triangles.begin() + ml.triangle_offset + ml.triangle_count * 3);
  }
  return parts;
}

Mesh cluster_mesh(const Mesh& mesh, const ClusterPart& part) {
  Mesh c;
  c.material = mesh.material;
  c.indices = part.indices;
  c.positions.reserve(part.vertices.size());
  for (uint32_t v : part.vertices) c.positions.push_back(mesh.positions[v]);
  if (mesh.has_normals())
    for (uint32_t v : part.vertices) c.normals.push_back(mesh.normals[v]);
  if (mesh.has_uvs())
    for (uint32_t v : part.vertices) c.uvs.push_back(mesh.uvs[v]);
  if (mesh.has_colors())
    for (uint32_t v : part.vertices) c.colors.push_back(mesh.colors[v]);
  return c;
}

}  // namespace lodstream::hierarchy
