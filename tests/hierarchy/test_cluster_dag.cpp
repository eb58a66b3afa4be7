// Cluster DAG invariants (cluster_dag.hpp): monotonic errors, containing spheres, crack-free cuts at many
// views and thresholds, the error bound against a brute-force distance, termination on awkward input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <span>
#include <tuple>

#include "hierarchy/bounding_sphere.hpp"
#include "hierarchy/cluster_dag.hpp"
#include "hierarchy/cut.hpp"
#include "support/brute_distance.hpp"
#include "support/shapes.hpp"

namespace lodstream::hierarchy {
namespace {

// Monotonic errors, containing spheres, shared pairs within a group, parents' pairs equal to the group's.
void check_invariants(const ClusterDag& dag) {
  for (const DagGroup& g : dag.groups) {
    for (uint32_t c : g.children) {
      const DagCluster& child = dag.clusters[c];
      EXPECT_GE(g.error, child.error);
      EXPECT_TRUE(sphere_contains(g.sphere, child.sphere)) << "group sphere misses a child's";
      EXPECT_EQ(child.parent_error, g.error);
      EXPECT_EQ(child.parent_sphere.radius, g.sphere.radius);
    }
    // Clusters of one group (one position shift in a package) agree on which shared positions are locked.
    std::map<std::tuple<float, float, float>, uint8_t> locked_at;
    for (uint32_t c : g.clusters)
      for (size_t v = 0; v < dag.clusters[c].mesh.positions.size(); ++v) {
        const glm::vec3 p = dag.clusters[c].mesh.positions[v];
        auto [it, fresh] = locked_at.emplace(std::make_tuple(p.x, p.y, p.z), dag.clusters[c].locked[v]);
        if (!fresh) {
          EXPECT_EQ(it->second, dag.clusters[c].locked[v]) << "siblings disagree on a locked position";
        }
      }
    for (uint32_t c : g.clusters) {
      EXPECT_EQ(dag.clusters[c].error, g.error);
      EXPECT_EQ(dag.clusters[c].sphere.radius, g.sphere.radius);
      for (const glm::vec3& p : dag.clusters[c].mesh.positions)
        EXPECT_LE(glm::length(p - g.sphere.center), g.sphere.radius * 1.000001f);
    }
  }
  for (const DagCluster& c : dag.clusters) {
    EXPECT_LE(c.mesh.triangle_count(), 128u);
    EXPECT_GE(c.parent_error, c.error);
  }
  for (uint32_t r : dag.roots) EXPECT_TRUE(std::isinf(dag.clusters[r].parent_error));
}

// What the random cuts of check_cuts drew, so that a test can check that they varied: how many distinct cut
// sizes, the levels drawn in some cut, and how many cuts drew clusters of two levels or more.
struct CutVariety {
  size_t sizes = 0;
  std::set<uint32_t> levels;
  size_t mixed = 0;
};

// Cuts for random eyes and thresholds: welded by position, their boundary edges must be the input's.
CutVariety check_cuts(const ClusterDag& dag, const Mesh& input, int cuts) {
  SurfaceWelder welder;
  const std::vector<uint32_t> input_ids = welder.weld(input);
  const std::vector<uint32_t>* input_part = &input_ids;
  const std::vector<uint64_t> reference = boundary_edges({&input_part, 1});
  std::vector<std::vector<uint32_t>> welded;
  for (const DagCluster& c : dag.clusters) welded.push_back(welder.weld(c.mesh));

  const Sphere all = sphere_of_points(input.positions);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<size_t> sizes;
  CutVariety variety;
  for (int i = 0; i < cuts; ++i) {
    CutView view;
    glm::dvec3 dir(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    view.eye = glm::dvec3(all.center) + glm::normalize(dir) * double(all.radius) * (0.5 + 30.0 * u(rng));
    const double tau = std::pow(10.0, -1.0 + 4.0 * u(rng));
    std::vector<const std::vector<uint32_t>*> parts;
    std::set<uint32_t> levels;
    for (size_t c = 0; c < dag.clusters.size(); ++c) {
      const DagCluster& k = dag.clusters[c];
      if (!in_cut(k.error, k.sphere, k.parent_error, k.parent_sphere, view, tau)) continue;
      parts.push_back(&welded[c]);
      levels.insert(k.level);
    }
    variety.levels.insert(levels.begin(), levels.end());
    variety.mixed += levels.size() > 1;
    EXPECT_FALSE(parts.empty());
    const std::string diff = compare_boundaries(boundary_edges(parts), reference, welder);
    EXPECT_EQ(diff, "") << "cut " << i << " (tau " << tau << ", " << parts.size() << " clusters)";
    if (!diff.empty()) break;
    sizes.push_back(parts.size());
  }
  std::sort(sizes.begin(), sizes.end());
  variety.sizes = size_t(std::unique(sizes.begin(), sizes.end()) - sizes.begin());
  return variety;
}

TEST(ClusterDag, SphereIsMonotonicAndCrackFree) {
  const Mesh mesh = test::sphere(1.0f, 64, 128);
  const ClusterDag dag = build_cluster_dag(mesh);
  EXPECT_EQ(dag.input_triangles, mesh.triangle_count());
  EXPECT_GE(dag.levels, 5u);
  size_t root_triangles = 0;
  for (uint32_t r : dag.roots) root_triangles += dag.clusters[r].mesh.triangle_count();
  EXPECT_LE(root_triangles, 512u);
  EXPECT_FALSE(dag.stalled);
  check_invariants(dag);
  EXPECT_GE(check_cuts(dag, mesh, 60).sizes, 10u);
}

TEST(ClusterDag, GridKeepsItsBoundaryInEveryCut) {
  Mesh mesh = test::grid(64);
  // Gently rolling, so that the simplification errors are real and vary over the grid: a flat grid's errors
  // are float rounding, and whether its cuts vary then depends on how that rounding falls.
  for (glm::vec3& p : mesh.positions) p.z = 0.02f * std::sin(9.0f * p.x) * std::cos(7.0f * p.y);
  mesh.normals.clear();
  // Halving per level (the counts below were measured so; at group_ratio 0.45 7 of 100 views mix levels).
  DagOptions options;
  options.group_ratio = 0.5;
  const ClusterDag dag = build_cluster_dag(mesh, options);
  EXPECT_GE(dag.levels, 4u);
  check_invariants(dag);
  // The cuts varied: every level is drawn by some cut, and many cuts mix levels (14 of 100 views).
  const CutVariety variety = check_cuts(dag, mesh, 100);
  EXPECT_EQ(variety.levels.size(), dag.levels);
  EXPECT_GE(variety.mixed, 8u);
}

TEST(ClusterDag, SeamsSurviveAndStayCrackFree) {
  const Mesh mesh = test::uv_sphere(1.0f, 48, 96);
  const ClusterDag dag = build_cluster_dag(mesh);
  check_invariants(dag);
  check_cuts(dag, mesh, 40);
  for (const DagCluster& c : dag.clusters) EXPECT_EQ(c.mesh.uvs.size(), c.mesh.positions.size());
}

// Both sides of every cluster's error bound: coarse clusters to the full-resolution surface, and that surface
// to the coarsest cut.
void check_error_bound(const Mesh& mesh, const ClusterDag& dag) {
  ASSERT_GE(dag.groups.size(), 2u);
  const std::vector<const Mesh*> full = {&mesh};
  // One-sided from every coarse cluster to the full-resolution surface.
  for (const DagCluster& c : dag.clusters) {
    if (c.level == 0) continue;
    for (const glm::dvec3& p : test::samples(c.mesh))
      EXPECT_LE(test::distance_to(p, full), double(c.error) * 1.0001 + 1e-6);
  }
  // Other side: from the full-resolution surface to the coarsest cut.
  std::vector<const Mesh*> roots;
  float root_error = 0.0f;
  for (uint32_t r : dag.roots)
    roots.push_back(&dag.clusters[r].mesh), root_error = std::max(root_error, dag.clusters[r].error);
  EXPECT_GT(root_error, 0.0f);
  for (const glm::dvec3& p : test::samples(mesh))
    EXPECT_LE(test::distance_to(p, roots), double(root_error) * 1.0001 + 1e-6);
}

TEST(ClusterDag, ErrorBoundHoldsAgainstBruteForceDistance) {
  const Mesh mesh = test::sphere(1.0f, 24, 48);
  check_error_bound(mesh, build_cluster_dag(mesh));
}

// `count` separate tetrahedra scattered in a box: many tiny closed components.
Mesh tetrahedra_soup(int count) {
  Mesh soup;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 10.0f);
  for (int k = 0; k < count; ++k) {  // separate tetrahedra (closed, 4 triangles each)
    const glm::vec3 o(u(rng), u(rng), u(rng));
    const uint32_t base = uint32_t(soup.positions.size());
    for (glm::vec3 d : {glm::vec3(0), glm::vec3(0.1f, 0, 0), glm::vec3(0, 0.1f, 0), glm::vec3(0, 0, 0.1f)})
      soup.positions.push_back(o + d);
    for (uint32_t i : {0u, 2u, 1u, 0u, 1u, 3u, 0u, 3u, 2u, 1u, 2u, 3u}) soup.indices.push_back(base + i);
  }
  return soup;
}

// DagOptions::inputs_final hands over every group exactly once, its input clusters already as the build
// leaves them, and most groups while later levels are still being built (what lets the bake encode beside
// the grouping), groups of level-0 clusters beside the second level's grouping.
void check_inputs_final(const Mesh& mesh) {
  struct Snapshot {
    std::vector<uint32_t> indices;
    std::vector<uint8_t> locked;
    float error, parent_error;
  };
  std::map<uint32_t, Snapshot> seen;                // by input cluster
  std::map<uint32_t, size_t> handed_with_clusters;  // by group: how many clusters the DAG had then
  size_t level0_beside_level2 = 0;
  DagOptions options;
  options.inputs_final = [&](const ClusterDag& dag, std::span<const uint32_t> groups) {
    for (uint32_t g : groups) {
      EXPECT_TRUE(handed_with_clusters.emplace(g, dag.clusters.size()).second) << "group " << g << " twice";
      for (uint32_t c : dag.groups[g].children) {
        const DagCluster& cluster = dag.clusters[c];
        EXPECT_EQ(cluster.parent_group, g);
        if (dag.levels == 2) level0_beside_level2 += cluster.level == 0;
        seen.emplace(c, Snapshot{cluster.mesh.indices, cluster.locked, cluster.error, cluster.parent_error});
      }
    }
  };
  const ClusterDag dag = build_cluster_dag(mesh, options);
  ASSERT_GE(dag.levels, 4u);
  EXPECT_EQ(handed_with_clusters.size(), dag.groups.size());
  EXPECT_EQ(seen.size() + dag.roots.size(), dag.clusters.size()) << "every cluster but the roots is an input";
  for (const auto& [c, s] : seen) {
    const DagCluster& cluster = dag.clusters[c];
    EXPECT_EQ(s.indices, cluster.mesh.indices);
    EXPECT_EQ(s.locked, cluster.locked) << "cluster " << c << " changed its locked flags after hand-over";
    EXPECT_EQ(s.error, cluster.error);
    EXPECT_EQ(s.parent_error, cluster.parent_error);
  }
  size_t early = 0;
  for (const auto& [g, clusters] : handed_with_clusters) early += clusters < dag.clusters.size();
  EXPECT_GE(early, dag.groups.size() / 2) << "groups should be handed over level by level";
  EXPECT_GT(level0_beside_level2, 0u) << "the second level's grouping should have level-0 clusters beside it";
  // The same build without the callback is the same DAG.
  const ClusterDag plain = build_cluster_dag(mesh);
  ASSERT_EQ(plain.clusters.size(), dag.clusters.size());
  for (size_t c = 0; c < dag.clusters.size(); ++c) {
    EXPECT_EQ(plain.clusters[c].locked, dag.clusters[c].locked);
    EXPECT_EQ(plain.clusters[c].mesh.indices, dag.clusters[c].mesh.indices);
  }
}

TEST(ClusterDag, GroupsAreHandedOverOnceWithFinalInputs) {
  check_inputs_final(test::sphere(1.0f, 64, 128));
  Mesh grid = test::grid(64);
  for (glm::vec3& p : grid.positions) p.z = 0.02f * std::sin(9.0f * p.x) * std::cos(7.0f * p.y);
  grid.normals.clear();
  check_inputs_final(grid);
}

TEST(ClusterDag, TerminatesOnNonManifoldAndManyTinyComponents) {
  const Mesh soup = tetrahedra_soup(600);
  const ClusterDag dag = build_cluster_dag(soup);
  check_invariants(dag);
  check_cuts(dag, soup, 20);
  // Edge collapse cannot reduce a closed tetrahedron: groups of them fall back to dropping whole
  // tetrahedra, so the build reaches a small root instead of stalling with 2400 root triangles.
  EXPECT_FALSE(dag.stalled);
  size_t root_triangles = 0;
  for (uint32_t r : dag.roots) root_triangles += dag.clusters[r].mesh.triangle_count();
  EXPECT_LE(root_triangles, 512u);
  EXPECT_TRUE(std::any_of(dag.groups.begin(), dag.groups.end(),
                          [](const DagGroup& g) { return g.outcome == GroupOutcome::components_dropped; }));
  check_error_bound(soup, dag);

  const Mesh odd = test::non_manifold();
  const ClusterDag small = build_cluster_dag(odd);
  EXPECT_EQ(small.roots.size(), small.clusters.size());
  check_cuts(small, odd, 5);

  EXPECT_TRUE(build_cluster_dag(Mesh{}).clusters.empty());
}

// Triangles with a repeated index are dropped before clustering, wherever they stand (first, inside, last):
// the level-0 clusters hold exactly the other triangles, each once.
TEST(ClusterDag, DegenerateTrianglesAreDroppedWherePlaced) {
  const Mesh sphere = test::sphere(1.0f, 16, 32);
  Mesh mesh = sphere;
  const size_t n = sphere.triangle_count();
  for (size_t t : {size_t(0), n / 3, n - 1}) mesh.indices[3 * t + 2] = mesh.indices[3 * t];
  const ClusterDag dag = build_cluster_dag(mesh);
  EXPECT_EQ(dag.input_triangles, n - 3);
  std::multiset<std::tuple<float, float, float, float, float, float, float, float, float>> kept, clustered;
  auto key = [](const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    return std::make_tuple(a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z);
  };
  for (size_t t = 0; t < n; ++t) {
    const uint32_t* i = &mesh.indices[3 * t];
    if (i[0] != i[1] && i[1] != i[2] && i[0] != i[2])
      kept.insert(key(mesh.positions[i[0]], mesh.positions[i[1]], mesh.positions[i[2]]));
  }
  for (const DagCluster& c : dag.clusters) {
    if (c.level != 0) continue;
    for (size_t k = 0; k < c.mesh.indices.size(); k += 3)
      clustered.insert(key(c.mesh.positions[c.mesh.indices[k]], c.mesh.positions[c.mesh.indices[k + 1]],
                           c.mesh.positions[c.mesh.indices[k + 2]]));
  }
  EXPECT_EQ(clustered, kept);
}

}  // namespace
}  // namespace lodstream::hierarchy
