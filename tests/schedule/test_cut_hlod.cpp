// Cut selection with an HLOD (schedule/cut.hpp): far away a scene of 256 objects is drawn as a bounded
// number of proxies; near, objects are drawn from their own nodes exactly as without HLOD (the crack-free
// rule inside an object is unaffected) and every object in view is covered once; unavailable proxies keep
// their parent drawn and are reported missing.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <map>

#include "schedule/cut.hpp"
#include "support/synthetic_dag.hpp"

using namespace lodstream;
using namespace lodstream::schedule;
using test::SyntheticDag;
using test::TestNodes;

namespace {

constexpr int kSide = 16;  // objects per row: 256 instances of the synthetic DAG, 20 units apart

struct HlodScene {
  SyntheticDag dag = SyntheticDag::make();  // its records, then the proxies'
  package::PackageScene with_hlod, without_hlod;
  std::vector<uint32_t> proxies;
};

// A quadtree of proxies over the kSide x kSide objects: leaves of 2 x 2 objects, 4 children per inner node;
// errors 0.5, 1.5, 4, 10 by level (the objects' roots have 0.1), spheres containing the children's.
HlodScene make_scene() {
  HlodScene s;
  std::vector<glm::mat4> transforms;
  for (int i = 0; i < kSide; ++i)
    for (int j = 0; j < kSide; ++j)
      transforms.push_back(glm::translate(glm::mat4(1.0f), glm::vec3(20.0f * i, 0.0f, 20.0f * j)));
  s.without_hlod = s.dag.scene(transforms);
  s.with_hlod = s.without_hlod;
  package::Representation rep;
  rep.kind = package::RepresentationKind::hlod;
  rep.levels = 4;
  const float errors[] = {0.5f, 1.5f, 4.0f, 10.0f};
  // Level by level: cell (i, j) of size `size` objects.
  std::map<std::tuple<int, int, int>, uint32_t> at;  // (size, i, j) -> node id
  for (int level = 0, size = 2; size <= kSide; ++level, size *= 2)
    for (int i = 0; i < kSide; i += size)
      for (int j = 0; j < kSide; j += size) {
        package::NodeRecord r;
        r.kind = package::NodeKind::hlod_proxy;
        r.representation = 1;
        r.level = uint32_t(level + 1);
        r.triangles = 200;
        r.error = errors[level];
        std::vector<Sphere> inner;
        for (int a = i; a < i + size; ++a)
          for (int b = j; b < j + size; ++b) {
            r.objects.push_back(uint32_t(a * kSide + b));
            const WorldSphere w = object_sphere(s.with_hlod, uint32_t(a * kSide + b));
            inner.push_back({glm::vec3(w.center), float(w.radius)});
          }
        std::sort(r.objects.begin(), r.objects.end());
        glm::vec3 c(0.0f);
        for (const Sphere& x : inner) c += x.center;
        c /= float(inner.size());
        float radius = 0.0f;
        for (const Sphere& x : inner) radius = std::max(radius, glm::length(x.center - c) + x.radius);
        r.sphere = {c, radius * 1.001f};
        const uint32_t id = uint32_t(s.dag.records.size());
        if (size > 2)
          for (int a = i; a < i + size; a += size / 2)
            for (int b = j; b < j + size; b += size / 2) {
              const uint32_t child = at.at({size / 2, a, b});
              r.children.push_back(child);
              s.dag.records[child].parents = {id};
              s.dag.records[child].parent_error = r.error;
              s.dag.records[child].parent_sphere = r.sphere;
            }
        s.dag.records.push_back(r);
        s.dag.intervals.push_back({0, 0});
        s.proxies.push_back(id);
        at[{size, i, j}] = id;
      }
  rep.roots = {s.proxies.back()};
  s.with_hlod.representations.push_back(rep);
  return s;
}

View view_from(glm::vec3 eye, glm::vec3 target) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.up = {0.0f, 1.0f, 0.0f};
  c.width = 1280;
  c.height = 720;
  return View::of(c);
}

const glm::vec3 kCentre(160.0f, 0.0f, 150.0f);

TEST(CutHlod, FarAwayDrawsFewProxiesInsteadOfEveryObject) {
  const HlodScene s = make_scene();
  TestNodes nodes(s.dag);
  const View far = view_from(kCentre + glm::vec3(0.0f, 3000.0f, 3000.0f), kCentre);
  const Cut without = select_cut(s.without_hlod, nodes, far, {1.0});
  const Cut with = select_cut(s.with_hlod, nodes, far, {1.0});
  EXPECT_GE(without.drawn.size(), 256u) << "every object's roots";
  EXPECT_LE(with.drawn.size(), 16u);
  for (const DrawnNode& d : with.drawn) {
    EXPECT_EQ(d.object, package::kNone);
    EXPECT_LE(d.error_px, 1.0);
  }
  EXPECT_TRUE(with.converged());
  EXPECT_LT(with.triangles, without.triangles);
}

TEST(CutHlod, NearObjectsAreDrawnAsWithoutHlodAndEachObjectOnce) {
  const HlodScene s = make_scene();
  TestNodes nodes(s.dag);
  // Low over one corner, looking across the field: near objects refine into their own nodes, far ones stay
  // under proxies.
  const View near = view_from({-5.0f, 4.0f, -5.0f}, kCentre);
  const Cut without = select_cut(s.without_hlod, nodes, near, {1.0});
  const Cut with = select_cut(s.with_hlod, nodes, near, {1.0});
  std::map<uint32_t, std::set<uint32_t>> own_with, own_without;
  std::vector<int> covered(kSide * kSide, 0);
  size_t proxies = 0;
  for (const DrawnNode& d : with.drawn) {
    if (d.object == package::kNone) {
      ++proxies;
      EXPECT_LE(d.error_px, 1.0);
      for (uint32_t o : s.dag.records[d.node].objects) ++covered[o];
    } else {
      own_with[d.object].insert(d.node);
    }
  }
  for (const DrawnNode& d : without.drawn) own_without[d.object].insert(d.node);
  EXPECT_GT(proxies, 0u);
  EXPECT_FALSE(own_with.empty()) << "the nearest objects are refined into their own nodes";
  for (const auto& [o, ids] : own_with) {
    EXPECT_EQ(ids, own_without[o]) << "object " << o << ": its own cut differs from the cut without HLOD";
    ++covered[o];
  }
  for (uint32_t o = 0; o < covered.size(); ++o) {
    if (with.objects[o] == ObjectState::culled) continue;
    EXPECT_EQ(covered[o], 1) << "object " << o << " is drawn " << covered[o] << " times";
  }
  EXPECT_LT(with.drawn.size(), without.drawn.size());
}

TEST(CutHlod, UnavailableProxiesKeepTheirParentAndAreMissing) {
  const HlodScene s = make_scene();
  TestNodes nodes(s.dag);
  const uint32_t root = s.proxies.back();
  for (uint32_t c : s.dag.records[root].children) nodes.unavailable.insert(c);
  const View mid = view_from(kCentre + glm::vec3(0.0f, 300.0f, 300.0f), kCentre);
  const Cut cut = select_cut(s.with_hlod, nodes, mid, {1.0});
  ASSERT_EQ(cut.drawn.size(), 1u);
  EXPECT_EQ(cut.drawn[0].node, root);
  EXPECT_GT(cut.drawn[0].error_px, 1.0) << "the view wants more than the root";
  ASSERT_FALSE(cut.missing.empty());
  for (const MissingNode& m : cut.missing)
    if (m.object == package::kNone && m.parent_error_px == cut.drawn[0].error_px) return;
  ADD_FAILURE() << "the root's children are not reported missing";
}

TEST(CutHlod, NothingOfCoveredObjectsBeforeTheHlodRootArrives) {
  const HlodScene s = make_scene();
  TestNodes nodes(s.dag);
  nodes.unavailable.insert(s.proxies.back());
  const View far = view_from(kCentre + glm::vec3(0.0f, 3000.0f, 3000.0f), kCentre);
  const Cut cut = select_cut(s.with_hlod, nodes, far, {1.0});
  EXPECT_TRUE(cut.drawn.empty());
  ASSERT_FALSE(cut.missing.empty());
  EXPECT_EQ(cut.missing[0].node, s.proxies.back());
  EXPECT_EQ(cut.missing[0].object, package::kNone);
}

TEST(CutHlod, AnHlodRootOutOfViewNeitherBlocksTheOthersNorIsAskedFor) {
  // The same quadtree with its four quadrants as roots; the far quadrant's root has not arrived and lies
  // behind a camera that looks at the near one.
  HlodScene s = make_scene();
  std::vector<uint32_t> quadrants;
  for (uint32_t id : s.proxies)
    if (s.dag.records[id].objects.size() == 64) quadrants.push_back(id);
  ASSERT_EQ(quadrants.size(), 4u);
  s.with_hlod.representations.back().roots = quadrants;
  TestNodes nodes(s.dag);
  const uint32_t far_root = quadrants.back();  // objects 8..15 x 8..15, centre (230, 0, 230)
  nodes.unavailable.insert(far_root);
  const View view = view_from({70.0f, 30.0f, 60.0f}, {70.0f, 0.0f, -100.0f});
  const Sphere& far = s.dag.records[far_root].sphere;
  ASSERT_FALSE(in_frustum({glm::dvec3(far.center), double(far.radius)}, view));
  const Cut cut = select_cut(s.with_hlod, nodes, view, {1.0});
  EXPECT_FALSE(cut.drawn.empty());
  for (const MissingNode& m : cut.missing) EXPECT_NE(m.node, far_root);
  for (uint32_t o = 0; o < cut.objects.size(); ++o) EXPECT_NE(cut.objects[o], ObjectState::incomplete) << o;
}

}  // namespace
