// Vertex clustering: triangle targets, locked vertices, the two-sided bound against a brute-force sampled
// Hausdorff distance, and the edge-collapse continuation (allow_topology_change).
#include <gtest/gtest.h>

#include <set>

#include "mesh_checks.hpp"
#include "simplify/cluster.hpp"
#include "support/shapes.hpp"

using namespace lodstream;
using namespace lodstream::test;
using simplify::cluster_mesh;
using simplify::Options;
using simplify::simplify_mesh;

namespace {

// Many small closed spheres side by side: edge collapse keeps at least a tetrahedron of each.
Mesh sphere_cloud(int n) {
  Mesh out;
  for (int i = 0; i < n; ++i) {
    Mesh s = lumpy(sphere(0.3f, 6, 12), unsigned(20 + i));
    uint32_t base = uint32_t(out.positions.size());
    for (auto& p : s.positions)
      out.positions.push_back(p + glm::vec3(0.5f * float(i % 5), 0.5f * float(i / 5), 0));
    for (uint32_t v : s.indices) out.indices.push_back(base + v);
  }
  return out;
}

TEST(Cluster, TargetAndBoundHold) {
  std::vector<Mesh> meshes = {lumpy(sphere(1.0f, 16, 32), 21), grid(16), sphere_cloud(10)};
  for (auto& p : meshes[1].positions) p.z = 0.2f * std::sin(6 * p.x) * std::cos(5 * p.y);
  for (size_t i = 0; i < meshes.size(); ++i)
    for (double ratio : {0.3, 0.1, 0.03}) {
      Options o;
      o.target_triangles = size_t(double(meshes[i].triangle_count()) * ratio);
      auto r = cluster_mesh(meshes[i], o);
      ASSERT_GT(r.mesh.triangle_count(), 0u);
      EXPECT_LE(r.mesh.triangle_count(), o.target_triangles) << i << " " << ratio;
      EXPECT_TRUE(r.target_reached);
      for (uint32_t v : r.mesh.indices) ASSERT_LT(v, r.mesh.vertex_count());
      EXPECT_LE(sampled_hausdorff(meshes[i], r.mesh), r.error_bound) << "mesh " << i << " ratio " << ratio;
      ASSERT_EQ(r.vertex_error.size(), r.mesh.vertex_count());
    }
}

TEST(Cluster, LockedVerticesStay) {
  Mesh in = lumpy(sphere(1.0f, 16, 32), 22);
  Options o;
  o.target_triangles = in.triangle_count() / 10;
  o.locked.assign(in.vertex_count(), 0);
  std::set<Key> locked;
  for (size_t v = 0; v < in.vertex_count(); v += 9) o.locked[v] = 1, locked.insert(key(in.positions[v]));
  auto r = cluster_mesh(in, o);
  std::set<Key> out;
  for (const auto& p : r.mesh.positions) out.insert(key(p));
  for (const auto& k : locked) EXPECT_TRUE(out.count(k));
  EXPECT_LT(r.mesh.triangle_count(), in.triangle_count() / 2);
  EXPECT_LE(sampled_hausdorff(in, r.mesh), r.error_bound);
}

TEST(Cluster, ContinuesWhereEdgeCollapseStops) {
  Mesh in = sphere_cloud(20);
  Options o;
  o.target_triangles = 30;  // below 20 tetrahedra
  auto stuck = simplify_mesh(in, o);
  EXPECT_FALSE(stuck.target_reached);
  EXPECT_GT(stuck.mesh.triangle_count(), 30u);
  o.allow_topology_change = true;
  auto r = simplify_mesh(in, o);
  EXPECT_TRUE(r.target_reached);
  EXPECT_LE(r.mesh.triangle_count(), 30u);
  EXPECT_GT(r.mesh.triangle_count(), 0u);
  EXPECT_LE(sampled_hausdorff(in, r.mesh), r.error_bound);
  EXPECT_GE(r.error_bound, stuck.error_bound);
}

}  // namespace
