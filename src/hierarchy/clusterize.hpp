// Splitting a mesh into clusters of at most N triangles and M vertices: triangles are first put in a
// spatial (Morton) order (spatial_sort.hpp), then each cluster grows greedily over shared vertices from the
// first unused triangle of that order (fewest new vertices first, then nearest), which keeps clusters
// spatially coherent with few boundary edges. The rule is that of meshoptimizer's meshlet builder, kept
// incremental (a frontier of candidate triangles instead of a rescan of the cluster's vertices per step and a
// k-d tree): meshopt_buildMeshlets was 10 % of an elephant_1m bake.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/mesh.hpp"

namespace lodstream::hierarchy {

struct ClusterPart {
  std::vector<uint32_t> vertices;  // mesh vertex of each cluster vertex
  std::vector<uint32_t> indices;   // three cluster-vertex numbers per triangle
};

// Clusters per run of the spatial order that is built on its own (in parallel); a run's last cluster may be
// partly filled and the cut between runs is ragged, so runs are long (1024 clusters).
inline constexpr size_t kChunkClusters = 1024;

// Clusters of `mesh`'s triangles, every triangle in exactly one. Cost: O(T) for the spatial order,
// then O(T) times a frontier of a few dozen triangles; meshes of more than kChunkClusters clusters use every
// core.
std::vector<ClusterPart> clusterize(const Mesh& mesh, size_t max_vertices, size_t max_triangles);

// The cluster's own mesh: positions and every attribute the mesh has, material copied.
Mesh cluster_mesh(const Mesh& mesh, const ClusterPart& part);

// Sets `cluster`'s material, positions and every attribute `mesh` has to those of `mesh`'s `vertices`
// (cluster_mesh without the indices). Cost: O(vertices).
void copy_cluster_vertices(const Mesh& mesh, std::span<const uint32_t> vertices, Mesh& cluster);

}  // namespace lodstream::hierarchy
