#include "hierarchy/clusterize.hpp"

#include <meshoptimizer.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <span>

namespace lodstream::hierarchy {

namespace {

// Meshlets of the triangles `indices` (a run of the spatial order) over `positions`, appended to `parts`.
void build_meshlets(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                    size_t max_vertices, size_t max_triangles, std::vector<ClusterPart>& parts) {
  const size_t bound = meshopt_buildMeshletsBound(indices.size(), max_vertices, max_triangles);
  std::vector<meshopt_Meshlet> meshlets(bound);
  std::vector<unsigned int> meshlet_vertices(bound * max_vertices);
  std::vector<unsigned char> meshlet_triangles(bound * max_triangles * 3);
  // cone_weight 0: clusters are grouped for simplification, not for backface culling.
  const size_t count = meshopt_buildMeshlets(
      meshlets.data(), meshlet_vertices.data(), meshlet_triangles.data(), indices.data(), indices.size(),
      &positions[0].x, positions.size(), sizeof(glm::vec3), max_vertices, max_triangles, 0.0f);
  for (size_t m = 0; m < count; ++m) {
    const meshopt_Meshlet& ml = meshlets[m];
    ClusterPart& part = parts.emplace_back();
    part.vertices.assign(meshlet_vertices.begin() + ml.vertex_offset,
                         meshlet_vertices.begin() + ml.vertex_offset + ml.vertex_count);
    part.indices.assign(meshlet_triangles.begin() + ml.triangle_offset,
                        meshlet_triangles.begin() + ml.triangle_offset + ml.triangle_count * 3);
  }
}

}  // namespace

std::vector<ClusterPart> clusterize(const Mesh& mesh, size_t max_vertices, size_t max_triangles) {
  std::vector<ClusterPart> parts;
  if (mesh.indices.empty()) return parts;
  std::vector<uint32_t> sorted(mesh.indices.size());
  meshopt_spatialSortTriangles(sorted.data(), mesh.indices.data(), mesh.indices.size(), &mesh.positions[0].x,
                               mesh.positions.size(), sizeof(glm::vec3));
  const size_t chunk_indices = 3 * kChunkClusters * max_triangles;
  if (sorted.size() <= chunk_indices) {
    build_meshlets(mesh.positions, sorted, max_vertices, max_triangles, parts);
    return parts;
  }
  // Runs of the spatial order in parallel, each over its own compact vertex range (the meshlet builder's
  // set-up is linear in the vertex count it is given).
  const size_t chunks = (sorted.size() + chunk_indices - 1) / chunk_indices;
  std::vector<std::vector<ClusterPart>> chunk_parts(chunks);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    const size_t begin = c * chunk_indices, end = std::min(sorted.size(), begin + chunk_indices);
    // mesh -> local vertex numbers in a per-thread table, reset after use (first use order).
    thread_local std::vector<uint32_t> local_of;
    if (local_of.size() < mesh.positions.size()) local_of.assign(mesh.positions.size(), UINT32_MAX);
    std::vector<uint32_t> local_to_mesh, indices(end - begin);
    for (size_t i = begin; i < end; ++i) {
      uint32_t& local = local_of[sorted[i]];
      if (local == UINT32_MAX) local = uint32_t(local_to_mesh.size()), local_to_mesh.push_back(sorted[i]);
      indices[i - begin] = local;
    }
    std::vector<glm::vec3> positions(local_to_mesh.size());
    for (size_t v = 0; v < local_to_mesh.size(); ++v) {
      positions[v] = mesh.positions[local_to_mesh[v]];
      local_of[local_to_mesh[v]] = UINT32_MAX;
    }
    build_meshlets(positions, indices, max_vertices, max_triangles, chunk_parts[c]);
    for (ClusterPart& part : chunk_parts[c])
      for (uint32_t& v : part.vertices) v = local_to_mesh[v];
  });
  for (auto& cp : chunk_parts)
    for (ClusterPart& part : cp) parts.push_back(std::move(part));
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
