#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.hpp"
#include "schedule/cut.hpp"
#include "support/synthetic_dag.hpp"

using namespace lodstream;
using namespace lodstream::schedule;
using test::SyntheticDag;
using test::TestNodes;

namespace {

// The eye near the x = 0 end of the strip, looking along it: near nodes need fine levels, far ones coarse.
View strip_view(glm::vec3 eye = {-1.0f, 0.5f, 1.0f}) {
  Camera c;
  c.eye = eye;
  c.target = {8.0f, 0.0f, 0.0f};
  c.width = 1280;
  c.height = 720;
  return View::of(c);
}

// Checks that the drawn nodes of `object` partition [0, 16) (exactly one covering) and are all available.
void expect_exact_covering(const Cut& cut, const SyntheticDag& dag, const TestNodes& nodes, uint32_t object) {
  std::vector<std::pair<double, double>> parts;
  for (const auto& d : cut.drawn)
    if (d.object == object) {
      parts.push_back(dag.intervals[d.node]);
      EXPECT_TRUE(nodes.available(d.node)) << "node " << d.node;
    }
  std::sort(parts.begin(), parts.end());
  ASSERT_FALSE(parts.empty());
  EXPECT_EQ(parts.front().first, 0.0);
  EXPECT_EQ(parts.back().second, 16.0);
  for (size_t i = 1; i < parts.size(); ++i)
    EXPECT_EQ(parts[i].first, parts[i - 1].second) << "gap or overlap at " << parts[i].first;
}

std::set<uint32_t> ancestors_or_self(const SyntheticDag& dag, uint32_t id) {
  std::set<uint32_t> out{id};
  std::vector<uint32_t> stack{id};
  while (!stack.empty()) {
    uint32_t n = stack.back();
    stack.pop_back();
    for (uint32_t p : dag.records[n].parents)
      if (out.insert(p).second) stack.push_back(p);
  }
  return out;
}

std::set<uint32_t> drawn_ids(const Cut& cut) {
  std::set<uint32_t> s;
  for (const auto& d : cut.drawn) s.insert(d.node);
  return s;
}

}  // namespace

TEST(Cut, AllAvailableIsTheThresholdRuleAndOneCovering) {
  SyntheticDag dag = SyntheticDag::make();
  TestNodes nodes(dag);
  auto scene = dag.scene({glm::mat4(1.0f)});
  View view = strip_view();
  std::set<size_t> sizes;
  for (double tau : {0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 30.0, 1000.0}) {
    Cut cut = select_cut(scene, nodes, view, {tau});
    SCOPED_TRACE(tau);
    expect_exact_covering(cut, dag, nodes, 0);
    EXPECT_TRUE(cut.converged());
    EXPECT_FALSE(cut.budget_limited);
    EXPECT_EQ(cut.tau, tau);
    EXPECT_EQ(cut.triangles, cut.ideal_triangles);
    uint64_t triangles = 0;
    for (const auto& d : cut.drawn) {
      const auto& r = dag.records[d.node];
      const double own = screen_error(r.error, to_world(r.sphere, glm::mat4(1.0f), 1.0), view);
      const double parents =
          screen_error(r.parent_error, to_world(r.parent_sphere, glm::mat4(1.0f), 1.0), view);
      EXPECT_DOUBLE_EQ(d.error_px, own);
      EXPECT_LE(own, tau) << "node " << d.node;  // DESIGN.md's rule, both halves
      EXPECT_GT(parents, tau) << "node " << d.node;
      triangles += d.triangles;
    }
    EXPECT_EQ(triangles, cut.triangles);
    sizes.insert(cut.drawn.size());
  }
  EXPECT_GE(sizes.size(), 4u);  // the taus above exercise several different cuts
}

TEST(Cut, MonotonicInTau) {
  SyntheticDag dag = SyntheticDag::make();
  TestNodes nodes(dag);
  auto scene = dag.scene({glm::mat4(1.0f)});
  for (glm::vec3 eye : {glm::vec3(-1, 0.5f, 1), glm::vec3(8, 2, 3), glm::vec3(17, 0, 0.5f)}) {
    View view = strip_view(eye);
    Cut finer = select_cut(scene, nodes, view, {0.1});
    for (double tau = 0.2; tau < 200; tau *= 1.5) {
      Cut coarser = select_cut(scene, nodes, view, {tau});
      EXPECT_LE(coarser.triangles, finer.triangles);
      const auto kept = drawn_ids(coarser);
      for (uint32_t n : drawn_ids(finer)) {  // every finer node is kept or replaced by an ancestor
        auto up = ancestors_or_self(dag, n);
        EXPECT_TRUE(std::any_of(up.begin(), up.end(), [&](uint32_t a) { return kept.count(a); }))
            << "node " << n << " at tau " << tau;
      }
      finer = coarser;
    }
  }
}

TEST(Cut, RespectsTheTriangleBudgetByRaisingTau) {
  SyntheticDag dag = SyntheticDag::make();
  TestNodes nodes(dag);
  auto scene = dag.scene({glm::mat4(1.0f)});
  View view = strip_view();
  Cut full = select_cut(scene, nodes, view, {0.05});
  ASSERT_EQ(full.triangles, 1600u);  // every leaf
  for (uint64_t budget : {200u, 400u, 700u, 1000u, 1500u}) {
    SCOPED_TRACE(budget);
    Cut cut = select_cut(scene, nodes, view, {0.05, budget});
    EXPECT_LE(cut.triangles, budget);
    EXPECT_TRUE(cut.budget_limited);
    EXPECT_GT(cut.tau, 0.05);
    expect_exact_covering(cut, dag, nodes, 0);
    // The budgeted cut is a threshold cut at the raised tau (nothing drawn above it).
    for (const auto& d : cut.drawn) EXPECT_LE(d.error_px, cut.tau);
  }
  Cut exact = select_cut(scene, nodes, view, {0.05, 1600});
  EXPECT_FALSE(exact.budget_limited);
  EXPECT_EQ(drawn_ids(exact), drawn_ids(full));
}

TEST(Cut, FallsBackToTheBestAvailableAncestorsAndReportsWhatIsMissing) {
  SyntheticDag dag = SyntheticDag::make();
  TestNodes nodes(dag);
  auto scene = dag.scene({glm::mat4(1.0f)});
  View view = strip_view();
  const double tau = 0.05;  // the ideal cut is every leaf
  nodes.unavailable = {5};  // one leaf of group {4-7}
  Cut cut = select_cut(scene, nodes, view, {tau});
  expect_exact_covering(cut, dag, nodes, 0);
  const auto drawn = drawn_ids(cut);
  EXPECT_TRUE(drawn.count(18) && drawn.count(19));  // b0, b1 stand for leaves 4-7
  for (uint32_t leaf : {4u, 6u, 7u}) EXPECT_FALSE(drawn.count(leaf));
  EXPECT_TRUE(drawn.count(3) && drawn.count(8));
  ASSERT_EQ(cut.missing.size(), 1u);
  EXPECT_EQ(cut.missing[0].node, 5u);
  EXPECT_TRUE(cut.missing[0].record_known);
  EXPECT_GT(cut.missing[0].parent_error_px, tau);
  EXPECT_FALSE(cut.converged());
  EXPECT_EQ(cut.ideal_triangles, 1600u);

  // A whole level missing in the middle: the roots are drawn and the level below is what to fetch, in
  // decreasing order of the error it removes.
  nodes.unavailable = {};
  for (uint32_t n = 23; n <= 27; ++n) nodes.unavailable.insert(n);  // e0, e1, f0, f1, g0
  cut = select_cut(scene, nodes, view, {tau});
  EXPECT_EQ(drawn_ids(cut), (std::set<uint32_t>{28, 29}));
  EXPECT_EQ(cut.missing.size(), 5u);
  for (size_t i = 1; i < cut.missing.size(); ++i)
    EXPECT_GE(cut.missing[i - 1].parent_error_px, cut.missing[i].parent_error_px);

  // A missing root: nothing of the object is drawn (no partial object), the root is what to fetch.
  nodes.unavailable = {28};
  cut = select_cut(scene, nodes, view, {tau});
  EXPECT_TRUE(cut.drawn.empty());
  EXPECT_EQ(cut.objects[0], ObjectState::incomplete);
  ASSERT_FALSE(cut.missing.empty());
  EXPECT_EQ(cut.missing[0].node, 28u);
  EXPECT_TRUE(std::isinf(cut.missing[0].parent_error_px));

  // An unknown record (index page not here): reported as such, once.
  nodes.unavailable = {};
  nodes.unknown = {8};
  cut = select_cut(scene, nodes, view, {tau});
  expect_exact_covering(cut, dag, nodes, 0);
  ASSERT_EQ(cut.missing.size(), 1u);
  EXPECT_EQ(cut.missing[0].node, 8u);
  EXPECT_FALSE(cut.missing[0].record_known);
}

TEST(Cut, PerObjectTransformsAndCulling) {
  SyntheticDag dag = SyntheticDag::make();
  TestNodes nodes(dag);
  const glm::mat4 near = glm::mat4(1.0f);
  const glm::mat4 far = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -200));
  const glm::mat4 behind = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 500));
  const glm::mat4 big_far = glm::scale(far, glm::vec3(10.0f));
  auto scene = dag.scene({near, far, behind, big_far});
  Camera c;
  c.eye = {8, 1, 20};
  c.target = {8, 0, 0};
  View view = View::of(c);
  Cut cut = select_cut(scene, nodes, view, {0.5});
  EXPECT_EQ(cut.objects[2], ObjectState::culled);
  size_t count[4] = {};
  for (const auto& d : cut.drawn) ++count[d.object];
  EXPECT_EQ(count[2], 0u);
  EXPECT_GT(count[0], count[1]);  // the far copy is coarser
  EXPECT_GT(count[3], count[1]);  // ten times larger: errors scale with it
  for (uint32_t o : {0u, 1u, 3u}) expect_exact_covering(cut, dag, nodes, o);
  // Missing nodes are per object and never of a culled one.
  nodes.unavailable = {0, 1, 2, 3};
  cut = select_cut(scene, nodes, view, {0.05});
  for (const auto& m : cut.missing) EXPECT_NE(m.object, 2u);
}

TEST(Cut, RejectsLinksThatAreNotGroupExchanges) {
  SyntheticDag dag = SyntheticDag::make();
  dag.records[0].parents = {16, 18};  // leaf 0's parents differ from its siblings'
  TestNodes nodes(dag);
  auto scene = dag.scene({glm::mat4(1.0f)});
  try {
    select_cut(scene, nodes, strip_view(), {0.05});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a group exchange"), std::string::npos) << e.what();
  }
}
