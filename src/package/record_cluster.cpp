#include "package/record_cluster.hpp"

#include <vector>

#include "core/error.hpp"

namespace lodstream::package {

DecodedNode extract_cluster(const DecodedNode& record, uint32_t cluster, const std::string& where) {
  const uint32_t clusters = record_clusters(record);
  if (cluster >= clusters) {
    throw Error(where + ": cluster " + std::to_string(cluster) + " out of range (its record holds " +
                std::to_string(clusters) + ")");
  }
  if (clusters == 1) return record;
  size_t first = 0;  // the cluster's first triangle
  for (uint32_t c = 0; c < cluster; ++c) first += record.cluster_triangles[c];
  const size_t count = record.cluster_triangles[cluster];
  const Mesh& in = record.mesh;
  const size_t V = in.positions.size();
  thread_local std::vector<uint32_t> compact;  // record vertex -> cluster vertex, UINT32_MAX = not yet used
  compact.assign(V, UINT32_MAX);
  DecodedNode out;
  Mesh& m = out.mesh;
  m.material = in.material;
  m.indices.resize(3 * count);
  std::vector<uint32_t> used;  // used[cluster vertex] = record vertex
  used.reserve(count + 2);
  for (size_t i = 0; i < 3 * count; ++i) {
    const uint32_t v = in.indices[3 * first + i];  // < V: the codec checked every index
    if (compact[v] == UINT32_MAX) compact[v] = uint32_t(used.size()), used.push_back(v);
    m.indices[i] = compact[v];
  }
  m.positions.reserve(used.size());
  for (uint32_t v : used) m.positions.push_back(in.positions[v]);
  if (in.has_normals())
    for (uint32_t v : used) m.normals.push_back(in.normals[v]);
  if (in.has_uvs())
    for (uint32_t v : used) m.uvs.push_back(in.uvs[v]);
  if (in.has_colors())
    for (uint32_t v : used) m.colors.push_back(in.colors[v]);
  if (!record.vertex_data.empty())
    for (uint32_t v : used) out.vertex_data.push_back(record.vertex_data[v]);
  out.index_end = uint32_t(used.size());
  return out;
}

}  // namespace lodstream::package
