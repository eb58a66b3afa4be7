// HLOD over many objects (hierarchy/hlod.hpp): errors monotonic up the tree and bounding the objects',
// spheres containing the children's and the proxies' own vertices, object sets that nest and partition, a
// bounded proxy size, and no HLOD for a single object; proxies keep their objects' material (UVs and colours
// interpolated) or, over several materials, their base colours as vertex colours; coarse objects stay out.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "hierarchy/bounding_sphere.hpp"
#include "hierarchy/hlod.hpp"
#include "simplify/simplify.hpp"
#include "support/brute_distance.hpp"
#include "support/shapes.hpp"

using namespace lodstream;
using namespace lodstream::hierarchy;

namespace {

// A `side` x `side` grid of small spheres (as their own coarse meshes) 3 units apart, error growing with the
// index so that the maximum is not always the first object's.
std::vector<HlodObject> sphere_field(int side) {
  std::vector<HlodObject> objects;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      HlodObject o;
      o.coarse = test::sphere(1.0f, 8, 16);
      const glm::vec3 at(3.0f * float(i), 0.0f, 3.0f * float(j));
      for (glm::vec3& p : o.coarse.positions) p += at;
      o.bounds = o.coarse.bounds();
      o.error = 0.001f * float(objects.size() % 7);
      o.sphere = sphere_of_points(o.coarse.positions);
      objects.push_back(std::move(o));
    }
  return objects;
}

TEST(Hlod, OneObjectOrNoneHasNoHlod) {
  EXPECT_EQ(build_hlod(sphere_field(1)).root, kNoHlodNode);
  EXPECT_TRUE(build_hlod(std::vector<HlodObject>{}).nodes.empty());
}

TEST(Hlod, ErrorsMonotonicSpheresContainingObjectsPartitioned) {
  const std::vector<HlodObject> objects = sphere_field(10);  // 100 objects
  HlodOptions options;
  options.position_tolerance = 1e-4f;
  const Hlod hlod = build_hlod(objects, options);
  ASSERT_NE(hlod.root, kNoHlodNode);
  ASSERT_EQ(hlod.root, 0u);
  EXPECT_EQ(hlod.nodes[hlod.root].parent, kNoHlodNode);
  // 100 objects, leaves of <= 4, 4 children each: at least 3 levels.
  EXPECT_GE(hlod.levels, 3u);
  std::vector<int> leaf_count(objects.size(), 0);
  for (uint32_t id = 0; id < hlod.nodes.size(); ++id) {
    const HlodNode& n = hlod.nodes[id];
    SCOPED_TRACE("node " + std::to_string(id));
    EXPECT_GT(n.mesh.triangle_count(), 0u);
    EXPECT_LE(n.mesh.triangle_count(), options.max_proxy_triangles);
    EXPECT_EQ(n.mesh.normals.size(), n.mesh.positions.size());
    for (const glm::vec3& p : n.mesh.positions)
      EXPECT_LE(glm::length(p - n.sphere.center), n.sphere.radius * (1.0f + 1e-6f));
    ASSERT_TRUE(std::is_sorted(n.objects.begin(), n.objects.end()));
    if (n.children.empty()) {
      EXPECT_EQ(n.level, 1u);
      EXPECT_LE(n.objects.size(), options.leaf_objects);
      for (uint32_t o : n.objects) {
        ++leaf_count[o];
        // The proxy replaces the object: at least its error, and a sphere around it.
        EXPECT_GE(n.error, objects[o].error);
        EXPECT_TRUE(sphere_contains(n.sphere, objects[o].sphere)) << "object " << o;
      }
      continue;
    }
    EXPECT_LE(n.children.size(), options.branching);
    std::vector<uint32_t> below;
    for (uint32_t c : n.children) {
      const HlodNode& child = hlod.nodes[c];
      EXPECT_EQ(child.parent, id);
      EXPECT_GT(c, id) << "breadth-first: parents first";
      EXPECT_GE(n.error, child.error) << "child " << c;
      EXPECT_LT(child.level, n.level);
      EXPECT_TRUE(sphere_contains(n.sphere, child.sphere)) << "child " << c;
      below.insert(below.end(), child.objects.begin(), child.objects.end());
    }
    std::sort(below.begin(), below.end());
    EXPECT_EQ(below, n.objects) << "an inner node's objects are the disjoint union of its children's";
  }
  // The leaves partition the objects, and the root stands for all of them.
  for (size_t o = 0; o < objects.size(); ++o) EXPECT_EQ(leaf_count[o], 1) << "object " << o;
  std::vector<uint32_t> all(objects.size());
  std::iota(all.begin(), all.end(), 0u);
  EXPECT_EQ(hlod.nodes[hlod.root].objects, all);
  // The root proxy is far coarser than the objects together (100 x 224 triangles).
  EXPECT_LE(hlod.nodes[hlod.root].mesh.triangle_count(), options.max_proxy_triangles);
}

TEST(Hlod, SplitsAlongTheLongestAxis) {
  // 16 objects on a line along x: the root's four children each hold a contiguous run of four.
  std::vector<HlodObject> objects;
  for (int i = 0; i < 16; ++i) {
    HlodObject o;
    o.coarse = test::sphere(0.5f, 6, 12);
    for (glm::vec3& p : o.coarse.positions) p.x += 2.0f * float(i);
    o.bounds = o.coarse.bounds();
    o.sphere = sphere_of_points(o.coarse.positions);
    objects.push_back(std::move(o));
  }
  const Hlod hlod = build_hlod(objects);
  ASSERT_EQ(hlod.nodes[hlod.root].children.size(), 4u);
  for (uint32_t c : hlod.nodes[hlod.root].children) {
    const std::vector<uint32_t>& run = hlod.nodes[c].objects;
    ASSERT_EQ(run.size(), 4u);
    EXPECT_EQ(run.back() - run.front(), 3u) << "a contiguous run along x";
  }
}

// Two UV spheres 3 units apart along x, of materials `material_a` and `material_b`.
std::vector<HlodObject> two_objects(uint32_t material_a, uint32_t material_b) {
  std::vector<HlodObject> objects;
  for (int i = 0; i < 2; ++i) {
    HlodObject o;
    o.coarse = test::uv_sphere(1.0f, 8, 16);
    o.coarse.material = i == 0 ? material_a : material_b;
    for (glm::vec3& p : o.coarse.positions) p.x += 3.0f * float(i);
    o.bounds = o.coarse.bounds();
    o.sphere = sphere_of_points(o.coarse.positions);
    objects.push_back(std::move(o));
  }
  return objects;
}

TEST(Hlod, AProxyOfOneTexturedMaterialKeepsItsUvs) {
  HlodOptions options;
  options.material_colors = {glm::vec4(0.8f), glm::vec4(0.8f)};
  options.mixed_material = 2;
  const Hlod hlod = build_hlod(two_objects(1, 1), options);
  ASSERT_NE(hlod.root, kNoHlodNode);
  const Mesh& proxy = hlod.nodes[hlod.root].mesh;
  EXPECT_EQ(proxy.material, 1u);
  ASSERT_EQ(proxy.uvs.size(), proxy.positions.size());
  // UVs interpolated from the sphere's [0,1]^2 parametrisation: they stay in range and vary.
  glm::vec2 lo(1.0f), hi(0.0f);
  for (const glm::vec2& uv : proxy.uvs) lo = glm::min(lo, uv), hi = glm::max(hi, uv);
  EXPECT_GE(lo.x, -1e-4f);
  EXPECT_LE(hi.y, 1.0f + 1e-4f);
  EXPECT_GT(hi.x - lo.x, 0.5f);
  EXPECT_GT(hi.y - lo.y, 0.5f);
}

TEST(Hlod, AProxyOfTwoMaterialsCarriesTheirColours) {
  HlodOptions options;
  const glm::vec4 red(1.0f, 0.0f, 0.0f, 1.0f), blue(0.0f, 0.0f, 1.0f, 1.0f);
  options.material_colors = {red, blue};
  options.mixed_material = 2;
  const Hlod hlod = build_hlod(two_objects(0, 1), options);
  ASSERT_NE(hlod.root, kNoHlodNode);
  const Mesh& proxy = hlod.nodes[hlod.root].mesh;
  EXPECT_EQ(proxy.material, 2u);
  ASSERT_EQ(proxy.colors.size(), proxy.positions.size());
  // The first sphere (x < 1.5) stays red, the second blue.
  size_t reddish = 0, bluish = 0;
  for (size_t v = 0; v < proxy.positions.size(); ++v) {
    const glm::vec4& c = proxy.colors[v];
    if (proxy.positions[v].x < 1.0f) reddish += c.r > 0.9f && c.b < 0.1f;
    if (proxy.positions[v].x > 2.0f) bluish += c.b > 0.9f && c.r < 0.1f;
  }
  EXPECT_GT(reddish, 0u);
  EXPECT_GT(bluish, 0u);
  for (size_t v = 0; v < proxy.positions.size(); ++v) {
    if (proxy.positions[v].x < 1.0f) {
      EXPECT_GT(proxy.colors[v].r, 0.5f) << "vertex " << v;
    }
    if (proxy.positions[v].x > 2.0f) {
      EXPECT_GT(proxy.colors[v].b, 0.5f) << "vertex " << v;
    }
  }
}

TEST(Hlod, ACoarseObjectStaysOutOfTheHlod) {
  std::vector<HlodObject> objects = sphere_field(4);  // 16 objects over about 12 units
  objects[5].error = 2.0f;  // > 100 x the median (0.003) and > 1 % of the diagonal (16)
  const Hlod hlod = build_hlod(objects);
  ASSERT_NE(hlod.root, kNoHlodNode);
  const std::vector<uint32_t>& covered = hlod.nodes[hlod.root].objects;
  EXPECT_EQ(covered.size(), 15u);
  EXPECT_EQ(std::count(covered.begin(), covered.end(), 5u), 0);
  EXPECT_LT(hlod.nodes[hlod.root].error, 2.0f) << "no proxy is as coarse as the object left out";
}

TEST(Hlod, ProxyErrorsFromCarriedRadiiBoundTheDistanceToTheFullResolution) {
  // 16 spheres of 528 triangles, each simplified to 64 as its coarse mesh carrying the simplifier's radii.
  std::vector<Mesh> full;
  std::vector<HlodObject> objects;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      Mesh m = test::sphere(1.0f, 12, 24);
      for (glm::vec3& p : m.positions) p += glm::vec3(3.0f * float(i), 0.4f * float(j), 3.0f * float(j));
      simplify::Options so;
      so.target_triangles = 64;
      simplify::Result r = simplify::simplify_mesh(m, so);
      HlodObject o;
      o.coarse = std::move(r.mesh);
      o.coarse_error = std::move(r.vertex_error);
      o.error = float(r.error_bound);
      o.bounds = m.bounds();
      o.sphere = sphere_of_points(m.positions);
      full.push_back(std::move(m));
      objects.push_back(std::move(o));
    }
  HlodOptions options;
  options.position_tolerance = 1e-4f;
  const Hlod hlod = build_hlod(objects, options);
  ASSERT_NE(hlod.root, kNoHlodNode);
  size_t tighter = 0;
  for (uint32_t id = 0; id < hlod.nodes.size(); ++id) {
    const HlodNode& n = hlod.nodes[id];
    SCOPED_TRACE("node " + std::to_string(id));
    std::vector<const Mesh*> below;
    for (uint32_t o : n.objects) below.push_back(&full[o]);
    const std::vector<const Mesh*> proxy{&n.mesh};
    // Both sides of the bound: the proxy to its objects' full resolution, and those to the proxy.
    for (const glm::dvec3& p : test::samples(n.mesh))
      ASSERT_LE(test::distance_to(p, below), double(n.error) * 1.0001);
    for (const Mesh* m : below)
      for (const glm::dvec3& p : test::samples(*m))
        ASSERT_LE(test::distance_to(p, proxy), double(n.error) * 1.0001);
    // Tighter than the largest replaced error plus the proxy's own bound (what the errors were before).
    double replaced = 0.0;
    for (uint32_t o : n.objects) replaced = std::max(replaced, double(objects[o].error));
    for (uint32_t c : n.children) replaced = std::max(replaced, double(hlod.nodes[c].error));
    tighter += double(n.error) < 0.9 * (replaced + n.simplification_bound);
  }
  EXPECT_GE(tighter, hlod.nodes.size() / 2);
}

}  // namespace
