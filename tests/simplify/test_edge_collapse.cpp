// Quadric edge collapse: topology, boundaries, seams, locks, flips, odd input, targets, and the two-sided
// error bound against a brute-force sampled Hausdorff distance.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <set>

#include "mesh_checks.hpp"
#include "simplify/simplify.hpp"
#include "support/shapes.hpp"

using namespace lodstream;
using namespace lodstream::test;
using simplify::Options;
using simplify::simplify_mesh;

namespace {

Options with_target(size_t triangles) {
  Options o;
  o.target_triangles = triangles;
  return o;
}

TEST(EdgeCollapse, ClosedManifoldStaysClosedAndManifold) {
  Mesh in = lumpy(sphere(1.0f, 24, 48), 1);
  for (double ratio : {0.5, 0.1, 0.02}) {
    size_t target = size_t(in.triangle_count() * ratio);
    auto r = simplify_mesh(in, with_target(target));
    EXPECT_TRUE(r.target_reached);
    EXPECT_LE(r.mesh.triangle_count(), target);
    EXPECT_GE(r.mesh.triangle_count() + target / 100 + 1, target);
    EXPECT_TRUE(is_edge_manifold(r.mesh)) << ratio;
    EXPECT_TRUE(boundary_edges(r.mesh).empty()) << ratio;
  }
}

TEST(EdgeCollapse, LinkConditionRefusesAPinch) {
  // A triangular bipyramid, poles locked: collapsing an equator edge (the cheapest) would join its ends'
  // third common neighbour, the other equator vertex, to x by two faces from each pole, each face's twin on
  // the same three vertices. The link condition (common neighbours = the removed faces' apexes) refuses it:
  // an equator vertex goes into a pole instead, to a tetrahedron. (Without the condition's first half, the
  // output is those twin faces.)
  Mesh in;
  in.positions = {{0, 0, 1}, {0, 0, -1}, {0.3f, 0, 0}, {-0.15f, 0.26f, 0}, {-0.15f, -0.26f, 0}};
  const uint32_t n = 0, s = 1, e0 = 2, e1 = 3, e2 = 4;
  in.indices = {n, e0, e1, n, e1, e2, n, e2, e0, s, e1, e0, s, e2, e1, s, e0, e2};
  Options o = with_target(4);  // one collapse
  o.locked = {1, 1, 0, 0, 0};  // the poles: only equator vertices are removed
  const auto r = simplify_mesh(in, o);
  std::set<std::array<Key, 3>> faces;
  for (size_t t = 0; t < r.mesh.triangle_count(); ++t) {
    std::array<Key, 3> f;
    for (int k = 0; k < 3; ++k) f[k] = key(r.mesh.positions[r.mesh.indices[3 * t + k]]);
    std::sort(f.begin(), f.end());
    EXPECT_TRUE(faces.insert(f).second) << "two faces on the same three vertices";
  }
  EXPECT_EQ(r.mesh.triangle_count(), 4u);
  EXPECT_TRUE(is_edge_manifold(r.mesh));
  EXPECT_TRUE(boundary_edges(r.mesh).empty());
}

TEST(EdgeCollapse, TwoSidedBoundHoldsOnManyMeshesAndRatios) {
  std::vector<Mesh> meshes = {lumpy(sphere(1.0f, 12, 24), 2), lumpy(uv_sphere(1.0f, 12, 24), 3),
                              cube_with_seams(4), grid(12)};
  for (auto& p : meshes[3].positions) p.z = 0.2f * std::sin(6 * p.x) * std::cos(5 * p.y);
  for (size_t i = 0; i < meshes.size(); ++i)
    for (double ratio : {0.5, 0.2, 0.05})
      for (int mode = 0; mode < 3; ++mode) {
        Options o = with_target(size_t(meshes[i].triangle_count() * ratio));
        if (mode == 1) o.half_edge = true;
        if (mode == 2) o.normal_weight = o.uv_weight = o.color_weight = 0;
        auto r = simplify_mesh(meshes[i], o);
        float measured = sampled_hausdorff(meshes[i], r.mesh);
        EXPECT_LE(measured, r.error_bound) << "mesh " << i << " ratio " << ratio << " mode " << mode;
        EXPECT_LE(r.error_bound, meshes[i].bounds().diagonal() * 1.01) << "mesh " << i << " ratio " << ratio;
        for (float e : r.vertex_error) EXPECT_LE(e, r.error_bound);
      }
}

// A second simplification started from the first one's radii (Options::vertex_error, as the cluster DAG does
// level after level) bounds its distance to the original, not only to its own input.
TEST(EdgeCollapse, CarriedRadiiBoundTheDistanceToTheFinerSurface) {
  std::vector<Mesh> meshes = {lumpy(sphere(1.0f, 16, 32), 4), grid(12)};
  for (auto& p : meshes[1].positions) p.z = 0.2f * std::sin(6 * p.x) * std::cos(5 * p.y);
  for (size_t i = 0; i < meshes.size(); ++i) {
    // A small second step: its own bound alone is below the first step's distance (lumpy sphere: 0.031
    // against 0.097), so the test fails when the radii are not carried.
    const auto first = simplify_mesh(meshes[i], with_target(meshes[i].triangle_count() / 10));
    Options o = with_target(first.mesh.triangle_count() * 97 / 100);
    o.vertex_error = first.vertex_error;
    const auto second = simplify_mesh(first.mesh, o);
    ASSERT_LT(second.mesh.triangle_count(), first.mesh.triangle_count()) << "mesh " << i;
    EXPECT_LE(sampled_hausdorff(meshes[i], second.mesh), second.error_bound) << "mesh " << i;
    EXPECT_LE(sampled_hausdorff(first.mesh, second.mesh), second.error_bound) << "mesh " << i;
  }
}

TEST(EdgeCollapse, BoundaryIsKept) {
  Mesh in = grid(16);
  for (auto& p : in.positions) p.z = 0.1f * std::sin(5 * p.x + 2 * p.y);
  auto r = simplify_mesh(in, with_target(60));
  EXPECT_TRUE(is_edge_manifold(r.mesh));
  // Every boundary edge stays on the square's border, and the corners stay.
  auto open = boundary_edges(r.mesh);
  ASSERT_FALSE(open.empty());
  for (const auto& [a, b] : open) {
    auto on_border = [](const Key& k) {
      auto [x, y, z] = k;
      return std::abs(x) < 1e-6f || std::abs(x - 1) < 1e-6f || std::abs(y) < 1e-6f || std::abs(y - 1) < 1e-6f;
    };
    EXPECT_TRUE(on_border(a) && on_border(b));
  }
  std::set<Key> corners;
  for (const auto& p : r.mesh.positions)
    if ((p.x == 0 || p.x == 1) && (p.y == 0 || p.y == 1)) corners.insert(key(p));
  EXPECT_EQ(corners.size(), 4u);
}

TEST(EdgeCollapse, UvSeamIsKept) {
  Mesh in = uv_sphere(1.0f, 16, 32);
  auto r = simplify_mesh(in, with_target(in.triangle_count() / 8));
  ASSERT_TRUE(r.mesh.has_uvs());
  EXPECT_TRUE(is_edge_manifold(r.mesh));
  // No triangle spans the seam in UV space, and the seam is still there (positions with two UVs).
  size_t seam_vertices = 0;
  std::map<Key, std::set<std::pair<float, float>>> uvs_at;
  for (size_t v = 0; v < r.mesh.vertex_count(); ++v)
    uvs_at[key(r.mesh.positions[v])].insert({r.mesh.uvs[v].x, r.mesh.uvs[v].y});
  for (const auto& [k, set] : uvs_at) seam_vertices += set.size() > 1;
  EXPECT_GE(seam_vertices, 2u);
  for (size_t t = 0; t < r.mesh.triangle_count(); ++t) {
    float u0 = r.mesh.uvs[r.mesh.indices[3 * t]].x, u1 = r.mesh.uvs[r.mesh.indices[3 * t + 1]].x,
          u2 = r.mesh.uvs[r.mesh.indices[3 * t + 2]].x;
    EXPECT_LT(std::max({u0, u1, u2}) - std::min({u0, u1, u2}), 0.9f);
  }
}

TEST(EdgeCollapse, LockedVerticesNeverMoveOrDisappear) {
  Mesh in = lumpy(sphere(1.0f, 16, 32), 4);
  Options o = with_target(100);
  o.locked.assign(in.vertex_count(), 0);
  std::set<Key> locked;
  for (size_t v = 0; v < in.vertex_count(); v += 7) o.locked[v] = 1, locked.insert(key(in.positions[v]));
  auto r = simplify_mesh(in, o);
  std::set<Key> out;
  for (const auto& p : r.mesh.positions) out.insert(key(p));
  for (const auto& k : locked) EXPECT_TRUE(out.count(k));
  EXPECT_LT(r.mesh.triangle_count(), in.triangle_count() / 2);
}

TEST(EdgeCollapse, ParallelRegionsGiveOneResultAndKeepTheGuarantees) {
  // Large enough for each pass's collapse loop to run on several regions of the mesh at once (both cores);
  // recording the collapses runs it serially, which gives the reference quality.
  Mesh in = lumpy(sphere(1.0f, 32, 64), 8);
  const size_t target = in.triangle_count() / 10;
  auto r1 = simplify_mesh(in, with_target(target));
  auto r2 = simplify_mesh(in, with_target(target));
  EXPECT_EQ(r1.mesh.indices, r2.mesh.indices);
  EXPECT_EQ(r1.mesh.positions, r2.mesh.positions);
  EXPECT_TRUE(r1.target_reached);
  EXPECT_LE(r1.mesh.triangle_count(), target);
  EXPECT_TRUE(is_edge_manifold(r1.mesh));
  EXPECT_TRUE(boundary_edges(r1.mesh).empty());
  EXPECT_LE(sampled_hausdorff(in, r1.mesh), r1.error_bound);
  // Quality against the serial order, over several meshes: on one mesh the sampled distance swings 0.9x to
  // 1.5x and the tracked bound (a maximum of accumulated radii) 0.3x to 3.8x between the two orders.
  double h_parallel = 0, h_serial = 0, bound_parallel = 0, bound_serial = 0;
  for (unsigned seed = 5; seed <= 10; ++seed) {
    Mesh m = lumpy(sphere(1.0f, 32, 64), seed);
    Options o = with_target(m.triangle_count() / 10), serial = o;
    serial.record_collapses = true;
    auto rp = simplify_mesh(m, o), rs = simplify_mesh(m, serial);
    h_parallel += sampled_hausdorff(m, rp.mesh), h_serial += sampled_hausdorff(m, rs.mesh);
    bound_parallel += rp.error_bound, bound_serial += rs.error_bound;
  }
  EXPECT_LE(h_parallel, 1.25 * h_serial) << h_serial;
  EXPECT_LE(bound_parallel, 1.5 * bound_serial) << bound_serial;
}

TEST(EdgeCollapse, OneThreadGivesTheResultOfAll) {
  // The weld, the quadrics, the classification and each pass's scans and sorts run on all cores in blocks;
  // the result must not depend on how many threads there are. A UV sphere (seams: wedge rings) with every
  // vertex also repeated exactly (duplicates to weld), large enough for several blocks of candidates.
  Mesh in = lumpy(uv_sphere(1.0f, 200, 400), 3);
  const size_t n = in.vertex_count();
  for (size_t v = 0; v < n; ++v) {
    in.positions.push_back(in.positions[v]), in.normals.push_back(in.normals[v]);
    in.uvs.push_back(in.uvs[v]);
  }
  for (size_t c = 0; c < in.indices.size(); c += 6)
    in.indices[c] += uint32_t(n);  // every other face's first corner
  const Options o = with_target(in.triangle_count() / 20);
  const auto all = simplify_mesh(in, o);
  simplify::Result one;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = simplify_mesh(in, o);
  }
  for (size_t v = 0; v < n; ++v) ASSERT_EQ(all.weld_remap[v], all.weld_remap[v + n]) << v;
  EXPECT_EQ(all.weld_remap, one.weld_remap);
  EXPECT_EQ(all.mesh.indices, one.mesh.indices);
  EXPECT_EQ(all.mesh.positions, one.mesh.positions);
  EXPECT_EQ(all.mesh.uvs, one.mesh.uvs);
  EXPECT_EQ(all.vertex_error, one.vertex_error);
  EXPECT_TRUE(all.target_reached);
}

TEST(EdgeCollapse, BorderCandidatesInPartsGiveTheSerialLoopsResult) {
  // The candidates the parallel regions leave go to one walk per thread (parts of the vertex numbers) before
  // the serial loop: the result must be the serial loop's, with any number of parts. Seams (wedge rings) and
  // a border (a grid) give every kind of candidate; 32 parts put most of them near a part's border.
  Mesh in = lumpy(uv_sphere(1.0f, 120, 240), 7);
  Mesh sheet = grid(160);
  for (auto& p : sheet.positions) p.z = 0.1f * std::sin(17 * p.x + 11 * p.y) + 3.0f;
  const uint32_t base = uint32_t(in.vertex_count());
  in.positions.insert(in.positions.end(), sheet.positions.begin(), sheet.positions.end());
  in.normals.resize(in.positions.size(), glm::vec3(0, 0, 1)), in.uvs.resize(in.positions.size());
  for (uint32_t v : sheet.indices) in.indices.push_back(base + v);
  const Options o = with_target(in.triangle_count() / 10);
  auto run = [&](size_t threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return simplify_mesh(in, o);
  };
  const auto one = run(1);
  for (size_t threads : {2, 32}) {
    const auto parts = run(threads);
    EXPECT_EQ(one.mesh.indices, parts.mesh.indices) << threads;
    EXPECT_EQ(one.mesh.positions, parts.mesh.positions) << threads;
    EXPECT_EQ(one.mesh.uvs, parts.mesh.uvs) << threads;
    EXPECT_EQ(one.vertex_error, parts.vertex_error) << threads;
  }
}

TEST(EdgeCollapse, NoTriangleFlips) {
  // On a star-shaped surface a flipped triangle faces the centre.
  Mesh in = lumpy(sphere(1.0f, 24, 48), 5);
  auto r = simplify_mesh(in, with_target(80));
  for (size_t t = 0; t < r.mesh.triangle_count(); ++t) {
    glm::vec3 a = r.mesh.positions[r.mesh.indices[3 * t]], b = r.mesh.positions[r.mesh.indices[3 * t + 1]],
              c = r.mesh.positions[r.mesh.indices[3 * t + 2]];
    EXPECT_GT(glm::dot(glm::cross(b - a, c - a), a + b + c), 0.0f) << t;
  }
}

TEST(EdgeCollapse, OddInputIsHandled) {
  // Non-manifold pieces, a second component, an unwelded copy (duplicate vertices) and degenerate triangles.
  Mesh in = non_manifold();
  Mesh s = lumpy(sphere(0.5f, 8, 16), 6);
  auto append_unwelded = [&](const Mesh& m, glm::vec3 offset) {
    for (size_t t = 0; t < m.indices.size(); ++t) {
      uint32_t v = m.indices[t];
      in.indices.push_back(uint32_t(in.positions.size()));
      in.positions.push_back(m.positions[v] + offset);
      if (in.has_normals()) in.normals.push_back(m.normals[v]);
    }
  };
  in.normals.clear();
  append_unwelded(s, {3, 0, 0});
  append_unwelded(s, {0, 3, 0});
  in.indices.insert(in.indices.end(), {0, 0, 1, 2, 2, 2});  // repeated vertices
  in.positions.push_back(in.positions[0]);                  // zero-area triangle with a duplicate
  in.indices.insert(in.indices.end(), {0, uint32_t(in.positions.size() - 1), 1});
  auto r = simplify_mesh(in, with_target(in.triangle_count() / 4));
  EXPECT_LT(r.mesh.triangle_count(), in.triangle_count() / 2);
  for (uint32_t i : r.mesh.indices) ASSERT_LT(i, r.mesh.vertex_count());
  EXPECT_LE(sampled_hausdorff(in, r.mesh), r.error_bound);
  // Empty input.
  auto e = simplify_mesh(Mesh{}, with_target(0));
  EXPECT_EQ(e.mesh.triangle_count(), 0u);
}

TEST(EdgeCollapse, WeldJoinsExactDuplicatesOnly) {
  // A fan around the origin whose centre is repeated: with the same normal (once as -0), and with another
  // normal (a wedge of the same position: not welded); a rim vertex repeated with its normal.
  Mesh in;
  in.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-0.0f, 0, -0.0f}, {0, 0, 0}, {1, 0, 0}, {-1, 0, 0}};
  in.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 1, 0}, {0, 0, 1}, {0, 0, 1}};
  in.indices = {0, 1, 2, 3, 2, 6, 4, 5, 2};
  auto r = simplify_mesh(in, with_target(in.triangle_count()));
  const std::vector<uint32_t>& w = r.weld_remap;
  ASSERT_EQ(w.size(), in.vertex_count());
  EXPECT_EQ(w[3], w[0]);
  EXPECT_EQ(w[5], w[1]);
  EXPECT_NE(w[4], w[0]);
  EXPECT_EQ(std::set<uint32_t>(w.begin(), w.end()).size(), 5u);
  EXPECT_EQ(r.mesh.triangle_count(), 3u);
}

TEST(EdgeCollapse, ErrorTargetIsNeverExceeded) {
  Mesh in = lumpy(sphere(1.0f, 16, 32), 7);
  for (double e : {0.05, 0.2, 0.5}) {
    Options o;
    o.max_error = e;
    auto r = simplify_mesh(in, o);
    EXPECT_LE(r.error_bound, e);
    EXPECT_TRUE(r.target_reached);
    EXPECT_LT(r.mesh.triangle_count(), in.triangle_count());
    EXPECT_LE(sampled_hausdorff(in, r.mesh), r.error_bound);
  }
  // Below the first collapse's bound nothing changes, and the bound is 0.
  Options o;
  o.max_error = 1e-4;
  auto r = simplify_mesh(in, o);
  EXPECT_EQ(r.mesh.triangle_count(), in.triangle_count());
  EXPECT_EQ(r.error_bound, 0.0);
}

TEST(EdgeCollapse, ShortfallIsReported) {
  // A cube with flat-shaded faces: every corner is a seam junction (locked), so it cannot go below 12.
  auto r = simplify_mesh(cube_with_seams(6), with_target(4));
  EXPECT_FALSE(r.target_reached);
  EXPECT_GE(r.mesh.triangle_count(), 12u);
  EXPECT_LT(r.mesh.triangle_count(), 6u * 72u);
}

TEST(EdgeCollapse, FlatRegionsCollapseWithoutError) {
  auto r = simplify_mesh(cube_with_seams(6), with_target(12));
  EXPECT_EQ(r.mesh.triangle_count(), 12u);
  EXPECT_LT(sampled_hausdorff(cube_with_seams(6), r.mesh), 1e-5f);
}

}  // namespace
