// Progressive steps (hierarchy/progressive_steps.hpp): the steps tile the ordered mesh, errors fall along
// them, and steps 0..j alone (their vertices, triangles and chains) give exactly the TOM prefix that
// simplify::extract gives for that vertex count: the chains carry every parent a prefix needs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <unordered_map>

#include "hierarchy/progressive_steps.hpp"
#include "simplify/progressive.hpp"
#include "support/shapes.hpp"

using namespace lodstream;
using namespace lodstream::test;

namespace {

using Tri = std::array<uint32_t, 3>;

std::vector<Tri> sorted_triangles(const std::vector<uint32_t>& indices) {
  std::vector<Tri> out;
  for (size_t t = 0; t + 2 < indices.size(); t += 3)
    out.push_back({indices[t], indices[t + 1], indices[t + 2]});
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Mesh> inputs() {
  Mesh bumpy = grid(24);
  for (auto& p : bumpy.positions) p.z = 0.2f * std::sin(6 * p.x) * std::cos(5 * p.y);
  return {uv_sphere(1.0f, 24, 48), bumpy, cube_with_seams(8)};
}

}  // namespace

TEST(ProgressiveSteps, StepsTileTheOrderAndEveryPrefixIsTheTomPrefix) {
  for (const Mesh& in : inputs()) {
    hierarchy::StepOptions options;
    options.min_step_triangles = 64;
    options.max_step_triangles = 256;
    const hierarchy::ProgressiveSteps steps = hierarchy::build_progressive_steps(in, options);
    const simplify::ProgressiveMesh pm = simplify::build_progressive(in, options.simplify);
    const size_t V = pm.mesh.vertex_count();
    ASSERT_EQ(steps.vertices, V);
    ASSERT_GE(steps.steps.size(), 4u);
    EXPECT_EQ(steps.steps[0].mesh.vertex_count(), pm.base_vertices) << "step 0 is the base mesh";
    EXPECT_EQ(steps.base.triangle_count(), steps.steps[0].mesh.triangle_count());
    std::vector<uint8_t> carried(V, 0);
    std::unordered_map<uint32_t, uint32_t> parent;  // chains of the steps so far
    std::vector<uint32_t> indices;
    size_t vertices = 0, triangles = 0;
    float previous_error = INFINITY;
    for (size_t k = 0; k < steps.steps.size(); ++k) {
      SCOPED_TRACE(k);
      const hierarchy::ProgressiveStep& s = steps.steps[k];
      ASSERT_EQ(s.first_vertex, vertices);
      ASSERT_EQ(s.first_triangle, triangles);
      ASSERT_GT(s.mesh.vertex_count(), 0u);
      vertices += s.mesh.vertex_count(), triangles += s.mesh.triangle_count();
      if (k > 0) {
        EXPECT_LE(s.mesh.triangle_count(), 3 * options.max_step_triangles) << "page-sized steps";
      }
      EXPECT_LE(s.error, previous_error) << "errors fall along the chain";
      previous_error = s.error;
      EXPECT_EQ(s.error, vertices < V ? pm.error[vertices] : 0.0f);
      if (vertices < V) {
        EXPECT_TRUE(pm.boundary[vertices]) << "a step ends between a seam's two wedges";
      }
      for (size_t v = 0; v < s.mesh.vertex_count(); ++v)
        EXPECT_EQ(s.mesh.positions[v], pm.mesh.positions[s.first_vertex + v]);
      EXPECT_TRUE(std::is_sorted(s.chains.begin(), s.chains.end()));
      for (const auto& [x, p] : s.chains) {
        EXPECT_GE(x, vertices);
        EXPECT_EQ(p, pm.parent[x]);
        EXPECT_FALSE(carried[x]++) << "vertex " << x << " carried twice";
        parent[x] = p;
      }
      // Steps 0..k alone: resolve every corner below the prefix's vertex count.
      indices.insert(indices.end(), s.mesh.indices.begin(), s.mesh.indices.end());
      std::vector<uint32_t> resolved = indices;
      for (uint32_t& c : resolved)
        while (c >= vertices) {
          auto it = parent.find(c);
          ASSERT_NE(it, parent.end()) << "corner " << c << " has no chain in steps 0.." << k;
          c = it->second;
        }
      EXPECT_EQ(sorted_triangles(resolved), sorted_triangles(simplify::extract(pm, vertices).indices));
    }
    EXPECT_EQ(vertices, V);
    EXPECT_EQ(triangles, pm.mesh.triangle_count());
    EXPECT_EQ(previous_error, 0.0f) << "the last step is the full mesh";
    for (const glm::vec3& p : pm.mesh.positions)
      EXPECT_LE(glm::length(p - steps.sphere.center), steps.sphere.radius * 1.00001f);
  }
}

TEST(ProgressiveSteps, NearTheBaseStepsDoubleTheTriangles) {
  const hierarchy::ProgressiveSteps steps = hierarchy::build_progressive_steps(uv_sphere(1.0f, 48, 96));
  ASSERT_GE(steps.steps.size(), 3u);
  size_t prefix = steps.steps[0].mesh.triangle_count();
  for (size_t k = 1; k + 1 < steps.steps.size(); ++k) {
    const size_t added = steps.steps[k].mesh.triangle_count();
    // clamp(prefix, 256, 2048) requested; whole collapses add up to a few triangles more or less.
    EXPECT_LE(added, std::clamp<size_t>(prefix, 256, 2048) + 8) << k;
    EXPECT_GE(added + 8, std::clamp<size_t>(prefix, 256, 2048)) << k;
    prefix += added;
  }
}

TEST(ProgressiveSteps, AnEmptyMeshHasNoSteps) {
  EXPECT_TRUE(hierarchy::build_progressive_steps(Mesh{}).steps.empty());
}
