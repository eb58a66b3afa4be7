// Clusterization (clusterize.hpp) of a mesh large enough to be built in parallel runs of the spatial order,
// and of one with degenerate triangles: every triangle in exactly one cluster, limits respected, cluster
// vertices mapping back to the mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "hierarchy/clusterize.hpp"
#include "support/shapes.hpp"

namespace lodstream::hierarchy {
namespace {

// Every triangle of `mesh` in exactly one part (same corners, same winding), each part within the limits
// and its vertices distinct mesh vertices.
void check_parts(const Mesh& mesh, const std::vector<ClusterPart>& parts, size_t max_vertices,
                 size_t max_triangles) {
  auto key = [](uint32_t a, uint32_t b, uint32_t c) {
    std::array<uint32_t, 3> k{a, b, c};
    std::rotate(k.begin(), std::min_element(k.begin(), k.end()), k.end());  // same winding, same key
    return k;
  };
  std::vector<std::array<uint32_t, 3>> input, clustered;
  for (size_t t = 0; t < mesh.indices.size(); t += 3)
    input.push_back(key(mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]));
  for (const ClusterPart& part : parts) {
    EXPECT_LE(part.vertices.size(), max_vertices);
    EXPECT_LE(part.indices.size(), 3 * max_triangles);
    EXPECT_FALSE(part.indices.empty());
    for (uint32_t v : part.vertices) ASSERT_LT(v, mesh.vertex_count());
    std::vector<uint32_t> vertices = part.vertices;
    std::sort(vertices.begin(), vertices.end());
    EXPECT_EQ(std::adjacent_find(vertices.begin(), vertices.end()), vertices.end()) << "a vertex twice";
    for (size_t i = 0; i < part.indices.size(); i += 3) {
      for (int k = 0; k < 3; ++k) ASSERT_LT(part.indices[i + k], part.vertices.size());
      clustered.push_back(key(part.vertices[part.indices[i]], part.vertices[part.indices[i + 1]],
                              part.vertices[part.indices[i + 2]]));
    }
  }
  std::sort(input.begin(), input.end());
  std::sort(clustered.begin(), clustered.end());
  EXPECT_EQ(clustered, input);
}

TEST(Clusterize, LargeMeshesSplitInRunsKeepEveryTriangleOnceWithinLimits) {
  const Mesh mesh = test::grid(300);  // 180000 triangles: more than one run of kChunkClusters clusters
  ASSERT_GT(mesh.triangle_count(), kChunkClusters * 128);
  const std::vector<ClusterPart> parts = clusterize(mesh, 128, 128);
  check_parts(mesh, parts, 128, 128);
  // Runs cost little: the clusters are about as many as the triangle limit allows.
  EXPECT_LE(parts.size(), mesh.triangle_count() / 128 * 103 / 100 + 8);
}

// Degenerate triangles (a repeated corner; grow_clusters tests corners for repeats only when the mesh has
// such a triangle) are clustered like the others: every triangle once, each vertex once per cluster, the
// limits kept.
TEST(Clusterize, DegenerateTrianglesAreClusteredOnceWithinLimits) {
  Mesh mesh = test::grid(24);
  for (size_t t = 0; t < mesh.indices.size(); t += 12) mesh.indices[t + 2] = mesh.indices[t];
  const std::vector<ClusterPart> parts = clusterize(mesh, 16, 32);
  check_parts(mesh, parts, 16, 32);
}

}  // namespace
}  // namespace lodstream::hierarchy
