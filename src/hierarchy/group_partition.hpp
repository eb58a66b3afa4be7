// Grouping clusters for simplification (Nanite's cluster groups): a graph with one node per cluster (weighted
// by its triangles) and one edge per pair of clusters that share boundary edges (weighted by how many), cut
// by METIS (recursive bisection; k-way up to 64 clusters) into parts of about `group_clusters` clusters, so
// that a group is compact and its outer border (what stays locked) short. Clusters that share no edge with
// any other (tiny components) are linked to their neighbours along a Morton curve over cluster centroids, so
// that they are grouped with what is near them. Up to 32 clusters are grouped as balanced runs of the Morton
// order of their centroids instead (METIS holds process-wide random state, so its calls are serialised; small
// graphs are most calls).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <utility>
#include <vector>

namespace lodstream::hierarchy {

// A cluster's boundary edge: (the edge's two position ids packed as min << 32 | max, the cluster).
using ClusterEdge = std::pair<uint64_t, uint32_t>;

// Sorts `edges` (by key, then cluster) when they are listed by increasing cluster and every position id is
// below `ids`: a radix sort (digits of smaller id * ids + larger id, each a stable counting-sort pass, so
// ties keep the cluster order). Cost: O(E) per pass, about log2(ids^2) / (log2(E) - 2) passes, one core, 16
// bytes per edge of scratch; the comparison sorts it replaces (O(E log E), on every core) took 0.7 CPU-s of
// an elephant_5m bake.
void sort_edges(std::vector<ClusterEdge>& edges, uint32_t ids);

// Groups of cluster numbers (0 .. triangles.size()-1), each cluster in exactly one group, no group empty.
// `edges` must be sorted (sort_edges). Cost: O(E) for the adjacency plus METIS (O(n log(n /
// group_clusters)), one core, one call at a time in the process).
std::vector<std::vector<uint32_t>> partition_clusters(std::span<const uint32_t> triangles,
                                                      std::span<const glm::vec3> centroids,
                                                      std::span<const ClusterEdge> edges,
                                                      size_t group_clusters);

}  // namespace lodstream::hierarchy
