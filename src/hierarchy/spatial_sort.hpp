// Triangles in spatial (Morton) order, the order the clusterizer grows clusters along (clusterize.hpp): each
// triangle's centroid (a + b + c) / 3 is placed on a 1024^3 grid over the centroids' bounding cube (cell
// = round((centroid - min) / extent * 1023), extent the box's largest side) and the triangles are sorted
// stably by the 30-bit Morton code of their cell (core/morton.hpp). This is exactly
// meshopt_spatialSortTriangles' order (meshoptimizer 0.18, which sorts by three serial radix passes); on a
// large mesh the codes are computed and sorted on every core, which took that serial sort off level 0's
// critical path of a cluster-DAG bake.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

namespace lodstream::hierarchy {

// `indices` (three per triangle, over `positions`) with the triangles in the order above. Cost: O(T) on
// every core (a counting sort by the code's top 10 bits, then each of the 1024 runs by two counting passes
// over its low 20 bits in cache: elephant_1m's level 0, 66 M instructions against 138 M sorting runs) for
// meshes of at least kParallelSortTriangles triangles, else one O(T log T) sort on the calling thread (on a
// DAG group's few hundred triangles about 38 k instructions fewer per call than meshoptimizer's three radix
// passes over 1024-entry histograms); 20 bytes per triangle of scratch.
std::vector<uint32_t> spatial_sort_triangles(std::span<const glm::vec3> positions,
                                             std::span<const uint32_t> indices);

// Meshes with fewer triangles are sorted on the calling thread (the parallel set-up costs more there).
inline constexpr size_t kParallelSortTriangles = size_t(1) << 16;

}  // namespace lodstream::hierarchy
