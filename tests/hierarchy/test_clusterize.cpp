// Clusterization (clusterize.hpp) of a mesh large enough to be built in parallel runs of the spatial order:
// every triangle in exactly one cluster, limits respected, cluster vertices mapping back to the mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "hierarchy/clusterize.hpp"
#include "support/shapes.hpp"

namespace lodstream::hierarchy {
namespace {

TEST(Clusterize, LargeMeshesSplitInRunsKeepEveryTriangleOnceWithinLimits) {
  const Mesh mesh = test::grid(300);  // 180000 triangles: more than one run of kChunkClusters clusters
  ASSERT_GT(mesh.triangle_count(), kChunkClusters * 128);
  const std::vector<ClusterPart> parts = clusterize(mesh, 128, 128);

  // Triangles as sorted corner triples of mesh vertices, from the input and from the clusters.
  auto key = [](uint32_t a, uint32_t b, uint32_t c) {
    std::array<uint32_t, 3> k{a, b, c};
    std::rotate(k.begin(), std::min_element(k.begin(), k.end()), k.end());  // same winding, same key
    return k;
  };
  std::vector<std::array<uint32_t, 3>> input, clustered;
  for (size_t t = 0; t < mesh.indices.size(); t += 3)
    input.push_back(key(mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]));
  for (const ClusterPart& part : parts) {
    EXPECT_LE(part.vertices.size(), 128u);
    EXPECT_LE(part.indices.size(), 3u * 128u);
    EXPECT_FALSE(part.indices.empty());
    for (uint32_t v : part.vertices) ASSERT_LT(v, mesh.vertex_count());
    for (size_t i = 0; i < part.indices.size(); i += 3) {
      for (int k = 0; k < 3; ++k) ASSERT_LT(part.indices[i + k], part.vertices.size());
      clustered.push_back(key(part.vertices[part.indices[i]], part.vertices[part.indices[i + 1]],
                              part.vertices[part.indices[i + 2]]));
    }
  }
  std::sort(input.begin(), input.end());
  std::sort(clustered.begin(), clustered.end());
  EXPECT_EQ(clustered, input);
  // Runs cost little: the clusters are about as many as the triangle limit allows.
  EXPECT_LE(parts.size(), mesh.triangle_count() / 128 * 103 / 100 + 8);
}

}  // namespace
}  // namespace lodstream::hierarchy
