// Cut selection over progressive meshes (schedule/cut.hpp): an object's drawn steps are a prefix 0..j, j the
// first step whose own error projects to <= tau (or the last available one); missing steps are reported with
// the previous prefix's projected error; the budget counts each step's own triangles; a cluster DAG object in
// the same scene is cut as before.
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

const float kErrors[] = {0.4f, 0.1f, 0.03f, 0.01f, 0.0f};
const uint32_t kTriangles[] = {50, 100, 200, 400, 800};
constexpr uint32_t kSteps = 5;

// The synthetic DAG (object 0, representation 0) and a progressive mesh of kSteps steps (object 1,
// representation 1, a unit sphere at x = 30): its step k is node first_step + k.
struct PmScene {
  SyntheticDag dag = SyntheticDag::make();
  package::PackageScene scene;
  uint32_t first_step = 0;

  PmScene() {
    first_step = uint32_t(dag.records.size());
    const Sphere sphere{{0.0f, 0.0f, 0.0f}, 1.0f};
    for (uint32_t k = 0; k < kSteps; ++k) {
      package::NodeRecord r;
      r.kind = package::NodeKind::progressive_step;
      r.representation = 1;
      r.level = kSteps - 1 - k;
      r.triangles = kTriangles[k];
      r.error = kErrors[k];
      r.sphere = r.parent_sphere = sphere;
      if (k > 0) r.parent_error = kErrors[k - 1], r.parents = {first_step + k - 1};
      if (k + 1 < kSteps) r.children = {first_step + k + 1};
      dag.records.push_back(r);
      dag.intervals.push_back({0.0, 0.0});
    }
    scene = dag.scene({glm::mat4(1.0f), glm::translate(glm::mat4(1.0f), glm::vec3(30.0f, 0.0f, 0.0f))});
    package::Representation rep;
    rep.kind = package::RepresentationKind::progressive_mesh;
    rep.bounds.add(glm::vec3(-0.5f));
    rep.bounds.add(glm::vec3(0.5f));
    rep.roots = {first_step};
    scene.representations.push_back(rep);
    scene.objects[1].representation = 1;
  }
  uint32_t step(uint32_t k) const { return first_step + k; }
  double error_px(uint32_t k, const View& view) const {
    return screen_error(kErrors[k], to_world(Sphere{{30.0f, 0.0f, 0.0f}, 1.0f}, glm::mat4(1.0f), 1.0), view);
  }
};

View view_from(glm::vec3 eye) {
  Camera c;
  c.eye = eye;
  c.target = {30.0f, 0.0f, 0.0f};
  c.width = 1280;
  c.height = 720;
  return View::of(c);
}

// Object 1's drawn nodes, in order.
std::vector<DrawnNode> drawn_steps(const Cut& cut) {
  std::vector<DrawnNode> out;
  for (const DrawnNode& d : cut.drawn)
    if (d.object == 1) out.push_back(d);
  return out;
}

// The step the rule ends at: the first whose own error projects to <= tau, else the last.
uint32_t rule_end(const PmScene& s, const View& view, double tau) {
  for (uint32_t k = 0; k < kSteps; ++k)
    if (s.error_px(k, view) <= tau) return k;
  return kSteps - 1;
}

}  // namespace

TEST(CutProgressive, AllAvailableDrawsThePrefixTheRuleEndsAt) {
  PmScene s;
  TestNodes nodes(s.dag);
  const View view = view_from({30.0f, -4.0f, 1.0f});
  std::set<uint32_t> ends;
  for (double tau : {0.05, 0.5, 2.0, 8.0, 30.0, 1e4}) {
    SCOPED_TRACE(tau);
    const Cut cut = select_cut(s.scene, nodes, view, {tau});
    EXPECT_TRUE(cut.converged());
    const uint32_t j = rule_end(s, view, tau);
    ends.insert(j);
    const std::vector<DrawnNode> steps = drawn_steps(cut);
    ASSERT_EQ(steps.size(), j + 1);
    uint64_t triangles = 0;
    for (uint32_t k = 0; k <= j; ++k) {
      EXPECT_EQ(steps[k].node, s.step(k));
      EXPECT_EQ(steps[k].refined, k < j) << k;
      EXPECT_EQ(steps[k].triangles, kTriangles[k]);
      EXPECT_NEAR(steps[k].error_px, s.error_px(k, view), 1e-9);
      triangles += kTriangles[k];
    }
    for (const DrawnNode& d : cut.drawn)
      if (d.object == 0) {
        triangles += d.triangles;
        EXPECT_FALSE(d.refined);
      }
    EXPECT_EQ(cut.triangles, triangles);
  }
  EXPECT_GE(ends.size(), 4u) << "the taus exercise most prefix lengths";
}

TEST(CutProgressive, AMissingStepEndsThePrefixAndIsReportedWithThePreviousError) {
  PmScene s;
  TestNodes nodes(s.dag);
  nodes.unavailable = {s.step(2)};
  const View view = view_from({30.0f, -4.0f, 1.0f});
  const double tau = 0.05;  // the rule wants every step
  ASSERT_EQ(rule_end(s, view, tau), kSteps - 1);
  const Cut cut = select_cut(s.scene, nodes, view, {tau});
  const std::vector<DrawnNode> steps = drawn_steps(cut);
  ASSERT_EQ(steps.size(), 2u) << "steps 0 and 1: the prefix stops before the missing step";
  EXPECT_TRUE(steps[0].refined);
  EXPECT_FALSE(steps[1].refined);
  // Missing: step 2 (to refine step 1's error) and, in the ideal cut beyond it, nothing else (3 and 4 are
  // available); the ideal cut draws every step.
  std::vector<MissingNode> missing;
  for (const MissingNode& m : cut.missing)
    if (m.object == 1) missing.push_back(m);
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_EQ(missing[0].node, s.step(2));
  EXPECT_NEAR(missing[0].parent_error_px, s.error_px(1, view), 1e-9);
  EXPECT_NEAR(missing[0].error_px, s.error_px(2, view), 1e-9);
  // Steps 3 and 4 missing too: reported in chain order of parent errors.
  nodes.unavailable = {s.step(2), s.step(3), s.step(4)};
  const Cut more = select_cut(s.scene, nodes, view, {tau});
  std::vector<uint32_t> order;
  for (const MissingNode& m : more.missing)
    if (m.object == 1) {
      order.push_back(m.node);
      EXPECT_NEAR(m.parent_error_px, s.error_px(m.node - s.first_step - 1, view), 1e-9);
    }
  EXPECT_EQ(order, (std::vector<uint32_t>{s.step(2), s.step(3), s.step(4)}));
}

TEST(CutProgressive, TheBudgetCountsEachStepsOwnTriangles) {
  PmScene s;
  TestNodes nodes(s.dag);
  const View view = view_from({30.0f, -4.0f, 1.0f});
  const Cut free = select_cut(s.scene, nodes, view, {0.05});
  ASSERT_EQ(drawn_steps(free).size(), kSteps);
  // Room for everything but the last step's 800 triangles.
  const Cut budgeted = select_cut(s.scene, nodes, view, {0.05, free.triangles - 1});
  EXPECT_TRUE(budgeted.budget_limited);
  EXPECT_LE(budgeted.triangles, free.triangles - 1);
  const std::vector<DrawnNode> steps = drawn_steps(budgeted);
  ASSERT_FALSE(steps.empty());
  EXPECT_LT(steps.size(), kSteps);
  // Its tau is the error of the refinement it stopped at; the cut is the threshold cut for that tau.
  const Cut at_tau = select_cut(s.scene, nodes, view, {budgeted.tau});
  EXPECT_EQ(drawn_steps(at_tau).size(), steps.size());
}

TEST(CutProgressive, LargerTauNeverDrawsMoreSteps) {
  PmScene s;
  TestNodes nodes(s.dag);
  for (glm::vec3 eye : {glm::vec3(30.0f, -3.0f, 1.0f), glm::vec3(0.0f, -40.0f, 5.0f)}) {
    const View view = view_from(eye);
    size_t previous = kSteps + 1;
    for (double tau : {0.01, 0.1, 1.0, 10.0, 100.0}) {
      const size_t n = drawn_steps(select_cut(s.scene, nodes, view, {tau})).size();
      EXPECT_LE(n, previous) << tau;
      EXPECT_GE(n, 1u);
      previous = n;
    }
  }
}

TEST(CutProgressive, AStepWhoseNextStepIsNotItsChainIsAnError) {
  PmScene s;
  s.dag.records[s.step(2)].parents = {s.step(0)};  // step 2 claims to refine step 0
  TestNodes nodes(s.dag);
  EXPECT_THROW(select_cut(s.scene, nodes, view_from({30.0f, -4.0f, 1.0f}), {0.05}), Error);
}
