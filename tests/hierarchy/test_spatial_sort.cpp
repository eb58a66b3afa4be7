// The spatial order of triangles (spatial_sort.hpp) is meshoptimizer's, on the parallel path (large meshes)
// and the serial one, including ties (triangles with the same centroid keep their input order) and a mesh
// whose centroids all coincide.
#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <random>

#include "hierarchy/spatial_sort.hpp"
#include "support/shapes.hpp"

namespace lodstream::hierarchy {
namespace {

std::vector<uint32_t> meshopt_order(const Mesh& mesh) {
  std::vector<uint32_t> sorted(mesh.indices.size());
  meshopt_spatialSortTriangles(sorted.data(), mesh.indices.data(), mesh.indices.size(), &mesh.positions[0].x,
                               mesh.positions.size(), sizeof(glm::vec3));
  return sorted;
}

// A sphere with its triangles shuffled, each followed later by a copy with the other winding (the same
// centroid, so the same Morton code: a tie that a stable sort keeps in input order).
Mesh shuffled_sphere_with_ties(int rings, int segments) {
  Mesh mesh = test::sphere(1.0f, rings, segments);
  const size_t n = mesh.triangle_count();
  std::vector<uint32_t> order(n);
  for (uint32_t t = 0; t < n; ++t) order[t] = t;
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  std::vector<uint32_t> indices;
  for (uint32_t t : order) indices.insert(indices.end(), &mesh.indices[3 * t], &mesh.indices[3 * t] + 3);
  for (uint32_t t : order)
    indices.insert(indices.end(), {mesh.indices[3 * t], mesh.indices[3 * t + 2], mesh.indices[3 * t + 1]});
  mesh.indices = std::move(indices);
  return mesh;
}

TEST(SpatialSort, LargeMeshIsSortedAsMeshoptimizerSortsIt) {
  const Mesh mesh = shuffled_sphere_with_ties(100, 200);  // 2 * 39600 triangles: the parallel path
  ASSERT_GE(mesh.triangle_count(), kParallelSortTriangles);
  const std::vector<uint32_t> sorted = spatial_sort_triangles(mesh.positions, mesh.indices);
  EXPECT_EQ(sorted, meshopt_order(mesh));
  EXPECT_NE(sorted, mesh.indices);  // the input was not in that order
}

// One triangle far away makes the grid's cube 1000x the sphere, so the sphere's triangles share a few of
// the code's top-10-bit runs: runs of thousands of triangles (sorted by counting passes) with ties.
TEST(SpatialSort, LongRunsAreSortedAsMeshoptimizerSortsIt) {
  Mesh mesh = shuffled_sphere_with_ties(100, 200);
  const uint32_t far = uint32_t(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), {{1000, 1000, 1000}, {1001, 1000, 1000}, {1000, 1001, 1000}});
  mesh.indices.insert(mesh.indices.end(), {far, far + 1, far + 2});
  const std::vector<uint32_t> sorted = spatial_sort_triangles(mesh.positions, mesh.indices);
  EXPECT_EQ(sorted, meshopt_order(mesh));
  EXPECT_NE(sorted, mesh.indices);
}

TEST(SpatialSort, SmallMeshIsSortedAsMeshoptimizerSortsIt) {
  const Mesh mesh = shuffled_sphere_with_ties(8, 16);
  ASSERT_LT(mesh.triangle_count(), kParallelSortTriangles);
  EXPECT_EQ(spatial_sort_triangles(mesh.positions, mesh.indices), meshopt_order(mesh));
}

// All centroids equal (a zero extent): every code is 0 and the order is the input's.
TEST(SpatialSort, CoincidentCentroidsKeepTheInputOrder) {
  Mesh mesh;
  mesh.positions = {{1, 2, 3}, {1, 2, 3}, {1, 2, 3}};
  for (size_t t = 0; t < kParallelSortTriangles + 5; ++t) mesh.indices.insert(mesh.indices.end(), {0, 1, 2});
  for (size_t t = 0; t < mesh.indices.size(); t += 3)
    std::rotate(&mesh.indices[t], &mesh.indices[t] + t % 3, &mesh.indices[t] + 3);
  EXPECT_EQ(spatial_sort_triangles(mesh.positions, mesh.indices), mesh.indices);
  EXPECT_EQ(meshopt_order(mesh), mesh.indices);
}

TEST(SpatialSort, EmptyMeshGivesNoIndices) {
  EXPECT_TRUE(spatial_sort_triangles({}, {}).empty());
}

}  // namespace
}  // namespace lodstream::hierarchy
