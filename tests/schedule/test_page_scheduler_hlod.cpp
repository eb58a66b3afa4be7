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
  std::vector<uint32_t> order;  // data pages as sent, one call of one page at a time
  for (int round = 0; round < 100; ++round) {
    const auto pages = s.next(reader.scene(), all, views, {1.0, UINT64_MAX, 1});
    if (pages.empty()) break;
    for (const PageRef& p : pages) {
      s.set_held(p.kind, p.id);
      if (p.kind == PageKind::data) order.push_back(p.id);
    }
  }
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
