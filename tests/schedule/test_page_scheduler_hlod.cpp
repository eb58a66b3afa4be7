// The PageScheduler over an HLOD (schedule/page_scheduler.hpp, schedule/cut.hpp): a leaf proxy is replaced
// by the roots of all its objects at once, so the scheduler sends those roots as one exchange, one after
// the other, never an object's roots while another object of the same leaf waits behind other pages (that
// would hold bytes the cut cannot draw). Scene: an HLOD root proxy over two leaf proxies of two objects
// each; one object of the first leaf is expensive (a large root page), its neighbour cheap.
#include <gtest/gtest.h>

#include <algorithm>
#include <glm/gtc/matrix_transform.hpp>

#include "support/dag_package.hpp"

using namespace lodstream;
using namespace lodstream::schedule;

namespace {

constexpr uint32_t kRoot = 0, kLeafA = 1, kLeafB = 2;  // proxies; node 3 + o is object o's root

package::NodeRecord proxy(float error, Sphere sphere, std::vector<uint32_t> objects) {
  package::NodeRecord r;
  r.kind = package::NodeKind::hlod_proxy;
  r.representation = 4;
  r.level = 1;
  r.triangles = 100;
  r.error = error;
  r.sphere = sphere;
  r.objects = std::move(objects);
  return r;
}

struct HlodPackage {
  package::PackageScene scene;
  std::vector<package::NodeRecord> records;
  HlodPackage() {
    const float x[] = {0.0f, 2.0f, 10.0f, 12.0f};
    for (uint32_t o = 0; o < 4; ++o) {
      package::Representation rep;
      rep.bounds.add(glm::vec3(-0.5f));
      rep.bounds.add(glm::vec3(0.5f));
      rep.roots = {3 + o};
      scene.representations.push_back(rep);
      scene.objects.push_back(
          {"o" + std::to_string(o), glm::translate(glm::mat4(1.0f), {x[o], 0.0f, 0.0f}), o});
    }
    package::Representation hlod;
    hlod.kind = package::RepresentationKind::hlod;
    hlod.roots = {kRoot};
    scene.representations.push_back(hlod);
    records.push_back(proxy(8.0f, {{6.0f, 0.0f, 0.0f}, 8.0f}, {0, 1, 2, 3}));
    records.push_back(proxy(4.0f, {{1.0f, 0.0f, 0.0f}, 2.0f}, {0, 1}));
    records.push_back(proxy(4.0f, {{11.0f, 0.0f, 0.0f}, 2.0f}, {2, 3}));
    records[kRoot].level = 2;
    records[kRoot].children = {kLeafA, kLeafB};
    for (uint32_t leaf : {kLeafA, kLeafB}) {
      records[leaf].parents = {kRoot};
      records[leaf].parent_error = records[kRoot].error;
      records[leaf].parent_sphere = records[kRoot].sphere;
    }
    for (uint32_t o = 0; o < 4; ++o) {
      package::NodeRecord r;
      r.representation = o;
      r.triangles = 50;
      r.error = 0.001f;
      r.sphere = {glm::vec3(0.0f), 0.9f};
      records.push_back(r);
    }
  }
};

View look(glm::vec3 eye, glm::vec3 target) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.up = {0.0f, 1.0f, 0.0f};
  return View::of(c);
}

// The data pages `s` sends for `views`, in order, asked for one page at a time (each held once chosen) until
// it has nothing more (at most 100 calls).
std::vector<uint32_t> send_one_by_one(PageScheduler& s, const package::PackageReader& reader,
                                      const PackageRecords& all, std::span<const WeightedView> views) {
  std::vector<uint32_t> order;
  for (int round = 0; round < 100; ++round) {
    const auto pages = s.next(reader.scene(), all, views, {1.0, UINT64_MAX, 1});
    if (pages.empty()) break;
    for (const PageRef& p : pages) {
      s.set_held(p.kind, p.id);
      if (p.kind == PageKind::data) order.push_back(p.id);
    }
  }
  return order;
}

}  // namespace

TEST(PageSchedulerHlod, ALeafsObjectsRootsAreSentTogether) {
  const HlodPackage h;
  // Object 0's root is cheap, object 1's expensive, objects 2 and 3 in between.
  auto reader =
      test::write_package("hlod.lods", h.records, h.scene, uint32_t(h.records.size()), [](uint32_t i) {
        return i == 3 ? 100 : i == 4 ? 20000 : 700;
      });
  PackageRecords all(reader);
  PageScheduler s(reader.root());
  const View view = look({6.0f, 0.0f, 30.0f}, {6.0f, 0.0f, 0.0f});
  const WeightedView views[] = {{view, 1.0, 0.0}};
  const std::vector<uint32_t> order = send_one_by_one(s, reader, all, views);
  // Everything the view needs arrives: the proxies, then every object's root.
  ASSERT_EQ(order.size(), h.records.size());
  auto at = [&](uint32_t node) {
    return size_t(std::find(order.begin(), order.end(), all.record(node)->page) - order.begin());
  };
  EXPECT_LT(at(kRoot), at(kLeafA));
  EXPECT_LT(at(kRoot), at(kLeafB));
  for (uint32_t leaf : {kLeafA, kLeafB}) {
    const uint32_t first = 3 + 2 * (leaf - kLeafA);  // the leaf's objects' roots: nodes first, first + 1
    EXPECT_EQ(std::max(at(first), at(first + 1)) - std::min(at(first), at(first + 1)), 1u)
        << "leaf " << leaf << ": its objects' roots are not sent one after the other";
  }
  // The cut of what arrived draws every object from its own root.
  const test::Held held(all, s);
  const Cut cut = select_cut(reader.scene(), held, view, {1.0});
  EXPECT_TRUE(cut.converged());
  EXPECT_EQ(cut.drawn.size(), 4u);
  for (const DrawnNode& d : cut.drawn) EXPECT_NE(d.object, package::kNone);
}

// An object covered by HLOD is drawn only once its leaf proxy is refined, which needs the roots of every
// object of the leaf (cut.hpp). So the finer levels of an object whose root the client holds wait until its
// leaf's other roots are sent: before, they went first (they were cheap), and the client could draw none of
// them (motorBike: 1 MB of objects' finer levels while the leaves waited for a few root pages).
TEST(PageSchedulerHlod, AnObjectsFinerLevelsWaitForItsLeafsOtherRoots) {
  HlodPackage h;
  constexpr uint32_t kRoot0 = 3, kRoot1 = 4, kFine0 = 7;  // object 0's root is refined by kFine0, kFine0 + 1
  h.records[kRoot0].error = 0.5f;
  h.records[kRoot0].children = {kFine0, kFine0 + 1};
  for (uint32_t i = 0; i < 2; ++i) {
    package::NodeRecord r;
    r.representation = 0;
    r.triangles = 50;
    r.error = 0.001f;
    r.sphere = {glm::vec3(0.0f, i ? 0.4f : -0.4f, 0.0f), 0.5f};
    r.parents = {kRoot0};
    r.parent_error = h.records[kRoot0].error;
    r.parent_sphere = h.records[kRoot0].sphere;
    h.records.push_back(r);
  }
  // Object 1's root is expensive, object 0's finer levels cheap.
  auto reader = test::write_package("hlod_fine.lods", h.records, h.scene, uint32_t(h.records.size()),
                                    [](uint32_t i) { return i == kRoot1 ? 20000 : 100; });
  PackageRecords all(reader);
  PageScheduler s(reader.root());
  for (uint32_t held : {kRoot, kLeafA, kLeafB, kRoot0}) s.set_held(PageKind::data, all.record(held)->page);
  const View view = look({1.0f, 0.0f, 4.0f}, {1.0f, 0.0f, 0.0f});
  const WeightedView views[] = {{view, 1.0, 0.0}};
  const std::vector<uint32_t> order = send_one_by_one(s, reader, all, views);
  auto at = [&](uint32_t node) {
    return size_t(std::find(order.begin(), order.end(), all.record(node)->page) - order.begin());
  };
  ASSERT_LT(at(kRoot1), order.size());
  ASSERT_LT(at(kFine0), order.size()) << "the view's ideal cut refines object 0";
  EXPECT_LT(at(kRoot1), at(kFine0));
  EXPECT_LT(at(kRoot1), at(kFine0 + 1));
}
