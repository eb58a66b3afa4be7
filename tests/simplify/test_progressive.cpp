// Totally ordered meshes: every vertex count gives a valid prefix equal to replaying the substitutions on
// the whole mesh, budgets are met, errors grow monotonically and bound the distance to the input.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "mesh_checks.hpp"
#include "simplify/progressive.hpp"
#include "support/shapes.hpp"

using namespace lodstream;
using namespace lodstream::test;
using simplify::build_progressive;
using simplify::extract;
using simplify::Options;
using simplify::ProgressiveMesh;
using simplify::vertex_count_for;

namespace {

using Tri = std::array<uint32_t, 3>;

// Brute force: substitute every vertex >= nv by its parent on all triangles, keep the non-degenerate ones.
std::vector<Tri> replay(const ProgressiveMesh& pm, size_t nv) {
  std::vector<Tri> out;
  for (size_t t = 0; t < pm.mesh.triangle_count(); ++t) {
    Tri c;
    for (int k = 0; k < 3; ++k) {
      uint32_t x = pm.mesh.indices[3 * t + k];
      while (x >= nv) x = pm.parent[x];
      c[k] = x;
    }
    if (c[0] != c[1] && c[1] != c[2] && c[0] != c[2]) out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Tri> triangles(const Mesh& m) {
  std::vector<Tri> out;
  for (size_t t = 0; t < m.triangle_count(); ++t)
    out.push_back({m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]});
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Mesh> inputs() {
  std::vector<Mesh> meshes = {lumpy(sphere(1.0f, 10, 20), 11), uv_sphere(1.0f, 10, 20), grid(10)};
  for (auto& p : meshes[2].positions) p.z = 0.2f * std::sin(6 * p.x) * std::cos(5 * p.y);
  return meshes;
}

TEST(Progressive, EveryPrefixIsValidAndMatchesReplay) {
  for (const Mesh& in : inputs()) {
    ProgressiveMesh pm = build_progressive(in, Options{});
    const size_t V = pm.mesh.vertex_count();
    ASSERT_EQ(pm.parent.size(), V);  // the only overhead: one index per vertex
    ASSERT_LT(pm.base_vertices, V / 4);
    EXPECT_EQ(pm.mesh.triangle_count(), in.triangle_count());
    for (size_t i = 0; i < V; ++i) {
      if (i < pm.base_vertices)
        EXPECT_EQ(pm.parent[i], UINT32_MAX);
      else
        EXPECT_LT(pm.parent[i], i);
    }
    for (size_t nv = pm.base_vertices; nv <= V; ++nv) {
      Mesh m = extract(pm, nv);
      ASSERT_EQ(m.vertex_count(), nv);
      for (uint32_t i : m.indices) ASSERT_LT(i, nv);
      auto got = triangles(m);
      for (const Tri& t : got) ASSERT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
      ASSERT_EQ(got, replay(pm, nv)) << "vertex count " << nv;
      // The prefix is exactly the first triangles of the stored order.
      for (size_t t = 0; t < m.triangle_count(); ++t)
        for (int k = 0; k < 3; ++k) {
          uint32_t x = pm.mesh.indices[3 * t + k];
          while (x >= nv) x = pm.parent[x];
          ASSERT_EQ(x, m.indices[3 * t + k]);
        }
    }
    EXPECT_EQ(triangles(extract(pm, V)), triangles(pm.mesh));
  }
}

TEST(Progressive, TriangleBudgetsAreMet) {
  for (const Mesh& in : inputs()) {
    ProgressiveMesh pm = build_progressive(in, Options{});
    const size_t base_tris = extract(pm, pm.base_vertices).triangle_count();
    for (size_t n = base_tris; n <= pm.mesh.triangle_count(); n += 7) {
      size_t nv = vertex_count_for(pm, n);
      size_t got = extract(pm, nv).triangle_count();
      EXPECT_LE(got, n);
      if (nv < pm.mesh.vertex_count()) {
        EXPECT_GT(extract(pm, nv + 1).triangle_count(), n);
      }
    }
  }
}

TEST(Progressive, ErrorsAreMonotonicAndBoundTheDistance) {
  // Meshes without seams: inside a seam step (two substitutions) the bound holds at the step's ends only.
  auto meshes = inputs();
  for (const Mesh& in : {meshes[0], meshes[2]}) {
    ProgressiveMesh pm = build_progressive(in, Options{});
    const size_t V = pm.mesh.vertex_count();
    for (size_t i = pm.base_vertices; i + 1 < V; ++i) EXPECT_GE(pm.error[i], pm.error[i + 1]);
    for (size_t nv : {V - V / 4, V / 2, V / 4, pm.base_vertices + 2}) {
      Mesh m = extract(pm, nv);
      EXPECT_LE(sampled_hausdorff(in, m), pm.error[nv]) << nv;
    }
  }
}

TEST(Progressive, LockedVerticesAreBase) {
  Mesh in = lumpy(sphere(1.0f, 10, 20), 12);
  Options o;
  o.locked.assign(in.vertex_count(), 0);
  for (size_t v = 0; v < in.vertex_count(); v += 5) o.locked[v] = 1;
  ProgressiveMesh pm = build_progressive(in, o);
  std::vector<Key> base;
  for (size_t i = 0; i < pm.base_vertices; ++i) base.push_back(key(pm.mesh.positions[i]));
  std::sort(base.begin(), base.end());
  for (size_t v = 0; v < in.vertex_count(); v += 5)
    EXPECT_TRUE(std::binary_search(base.begin(), base.end(), key(in.positions[v])));
}

}  // namespace
