#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "runtime/quality.hpp"
#include "support/synthetic_dag.hpp"

using namespace lodstream;
using namespace lodstream::runtime;

namespace {
// 200x100 viewport, 90° vertical: focal 50 px, tan_half_x = 2.
View test_view() {
  Camera c;
  c.eye = {0, 0, 0};
  c.target = {0, 0, -1};
  c.fov_y_degrees = 90.0f;
  c.width = 200;
  c.height = 100;
  return View::of(c);
}
}  // namespace

TEST(Quality, ProjectedAreaOfADiscInsideAtAnEdgeAndInACorner) {
  View v = test_view();
  const double pi = 3.14159265358979;
  // On the axis at distance 10, radius 1: disc radius 50 / sqrt(99).
  EXPECT_NEAR(projected_area({{0, 0, -10}, 1.0}, v), pi * 2500.0 / 99.0, 1e-3 * pi * 2500.0 / 99.0);
  // Centre projected onto the left edge (x / z = -2): half of the disc.
  WorldSphere edge{{-20, 0, -10}, 1.0};
  const double rho = 50.0 / std::sqrt(500.0 - 1.0);
  EXPECT_NEAR(projected_area(edge, v), 0.5 * pi * rho * rho, 1e-3 * pi * rho * rho);
  // Centre projected onto the top-left corner (x / z = -2, y / z = 1): a quarter.
  WorldSphere corner{{-20, 10, -10}, 1.0};
  const double rho_c = 50.0 / std::sqrt(600.0 - 1.0);
  EXPECT_NEAR(projected_area(corner, v), 0.25 * pi * rho_c * rho_c, 1e-3 * pi * rho_c * rho_c);
  // Around the eye: the whole viewport; behind: nothing; far outside: nothing.
  EXPECT_DOUBLE_EQ(projected_area({{0, 0, 0.5}, 1.0}, v), 200.0 * 100.0);
  EXPECT_DOUBLE_EQ(projected_area({{0, 0, 10}, 1.0}, v), 0.0);
  EXPECT_DOUBLE_EQ(projected_area({{-100, 0, -10}, 1.0}, v), 0.0);
}

TEST(Quality, ProjectedAreaClipsTheDiscExactly) {
  View v = test_view();  // focal 50 px, centre (100, 50)
  // Centre 2 px right of the left edge (x / z = (2 - 100) / 50): the part of the disc right of a chord at
  // distance 2 from its centre on the other side, rho^2 (pi - acos(2 / rho)) + 2 sqrt(rho^2 - 4).
  const double x = (2.0 - 100.0) / 5.0;
  const double rho = 50.0 / std::sqrt(x * x + 100.0 - 1.0);
  const double chord =
      rho * rho * (std::acos(-1.0) - std::acos(2.0 / rho)) + 2.0 * std::sqrt(rho * rho - 4.0);
  EXPECT_NEAR(projected_area({{x, 0, -10}, 1.0}, v), chord, 1e-12 * chord);
  // A disc of radius 189 px about the viewport's centre covers all of it (the corners are 112 px away).
  EXPECT_NEAR(projected_area({{0, 0, -3}, 2.9}, v), 200.0 * 100.0, 1e-9);
}

TEST(Quality, BenefitRatioAndPixelErrorOfHandMadeCuts) {
  // Two objects, each one node with its own sphere equal to the object's bounding sphere.
  package::NodeRecord a, b;
  a.sphere = b.sphere = {{0, 0, 0}, 1.0f};
  a.triangles = b.triangles = 10;
  struct Nodes : NodeSource {
    std::vector<package::NodeRecord> r;
    const package::NodeRecord* record(uint32_t id) const override { return &r.at(id); }
    bool available(uint32_t) const override { return true; }
  } nodes;
  nodes.r = {a, b};
  package::PackageScene scene;
  package::Representation rep;
  rep.bounds.add(glm::vec3(-1.0f / std::sqrt(3.0f)));  // half diagonal 1: the object sphere is the node's
  rep.bounds.add(glm::vec3(1.0f / std::sqrt(3.0f)));
  scene.representations = {rep};
  scene.objects = {{"near", glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -10)), 0},
                   {"far", glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -20)), 0},
                   {"behind", glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 20)), 0}};
  View v = test_view();
  const double a0 = projected_area(object_sphere(scene, 0), v),
               a1 = projected_area(object_sphere(scene, 1), v);
  ASSERT_GT(a0, 3.0 * a1);

  Cut cut;
  cut.objects = {ObjectState::drawn, ObjectState::drawn, ObjectState::culled};
  cut.drawn = {{0, 0, 0.5, 10}, {1, 1, 4.0, 10}};  // tau 1: near at tau/2 (alpha 1), far at 4 tau (alpha 1/4)
  FrameQuality q = frame_quality(scene, nodes, cut, v, 1.0);
  EXPECT_EQ(q.visible_objects, 2u);
  EXPECT_NEAR(q.benefit_ratio, (a0 * 1.0 + a1 * 0.25) / (a0 + a1), 1e-12);
  EXPECT_DOUBLE_EQ(q.pixel_error_max, 4.0);
  EXPECT_DOUBLE_EQ(q.pixel_error_mean, 2.25);

  // Nothing of the far one drawn (a root missing): alpha 0, and it leaves the pixel error.
  cut.objects[1] = ObjectState::incomplete;
  cut.drawn = {{0, 0, 0.5, 10}};
  q = frame_quality(scene, nodes, cut, v, 1.0);
  EXPECT_NEAR(q.benefit_ratio, a0 / (a0 + a1), 1e-12);
  EXPECT_DOUBLE_EQ(q.pixel_error_max, 0.5);
  EXPECT_DOUBLE_EQ(q.pixel_error_mean, 0.5);

  // Everything at tau or better: exactly 1.
  cut.objects[1] = ObjectState::drawn;
  cut.drawn = {{0, 0, 1.0, 10}, {1, 1, 0.0, 10}};
  EXPECT_DOUBLE_EQ(frame_quality(scene, nodes, cut, v, 1.0).benefit_ratio, 1.0);
}

TEST(Quality, AProgressivePrefixIsDrawnAtItsLastStepsError) {
  // One object drawn as progressive steps 0..2 (nodes 0, 1, 2; steps 0 and 1 refined by the next one).
  struct Nodes : NodeSource {
    std::vector<package::NodeRecord> r = std::vector<package::NodeRecord>(3);
    const package::NodeRecord* record(uint32_t id) const override { return &r.at(id); }
    bool available(uint32_t) const override { return true; }
  } nodes;
  for (package::NodeRecord& n : nodes.r) {
    n.kind = package::NodeKind::progressive_step;
    n.sphere = {{0, 0, 0}, 1.0f};
  }
  package::PackageScene scene;
  package::Representation rep;
  rep.kind = package::RepresentationKind::progressive_mesh;
  rep.bounds.add(glm::vec3(-0.5f));
  rep.bounds.add(glm::vec3(0.5f));
  scene.representations = {rep};
  scene.objects = {{"o", glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -10)), 0}};
  Cut cut;
  cut.objects = {ObjectState::drawn};
  cut.drawn = {{0, 0, 8.0, 100, true}, {0, 1, 2.0, 100, true}, {0, 2, 0.5, 200, false}};
  FrameQuality q = frame_quality(scene, nodes, cut, test_view(), 1.0);
  EXPECT_DOUBLE_EQ(q.benefit_ratio, 1.0) << "step 2 is within tau; the coarser steps it refines do not count";
  EXPECT_DOUBLE_EQ(q.pixel_error_max, 0.5);
  cut.drawn.pop_back();
  cut.drawn.back().refined = false;  // the prefix ends at step 1 (2 px)
  q = frame_quality(scene, nodes, cut, test_view(), 1.0);
  EXPECT_DOUBLE_EQ(q.benefit_ratio, 0.5);
  EXPECT_DOUBLE_EQ(q.pixel_error_max, 2.0);
}

TEST(Quality, AreaWeightedOverTheDrawnNodesOfASelectedCut) {
  test::SyntheticDag dag = test::SyntheticDag::make();
  test::TestNodes nodes(dag);
  auto scene = dag.scene({glm::mat4(1.0f)});
  Camera c;
  c.eye = {-1.0f, 0.5f, 1.0f};
  c.target = {8.0f, 0.0f, 0.0f};
  View v = View::of(c);
  const double tau = 0.5;
  Cut ideal = select_cut(scene, nodes, v, {tau});
  EXPECT_DOUBLE_EQ(frame_quality(scene, nodes, ideal, v, tau).benefit_ratio, 1.0);
  // Coarser than wished (a level missing): alpha is the area-weighted mean of tau / e_px of the roots.
  for (uint32_t n = 23; n <= 27; ++n) nodes.unavailable.insert(n);
  Cut coarse = select_cut(scene, nodes, v, {tau});
  ASSERT_EQ(coarse.drawn.size(), 2u);
  double wsum = 0.0, asum = 0.0;
  for (const auto& d : coarse.drawn) {
    const double a = projected_area(to_world(dag.records[d.node].sphere, glm::mat4(1.0f), 1.0), v);
    wsum += a;
    asum += a * std::min(1.0, tau / d.error_px);
  }
  FrameQuality q = frame_quality(scene, nodes, coarse, v, tau);
  EXPECT_NEAR(q.benefit_ratio, asum / wsum, 1e-12);
  EXPECT_LT(q.benefit_ratio, 1.0);
  EXPECT_DOUBLE_EQ(q.pixel_error_max, std::max(coarse.drawn[0].error_px, coarse.drawn[1].error_px));
}

TEST(Quality, ObjectsCoveredByADrawnProxyTakeItsError) {
  // Objects 0 and 1 under one HLOD proxy (node 2) drawn at 4 tau; object 2 drawn on its own at tau / 2;
  // object 3 under the proxy but culled: it does not count.
  package::NodeRecord own, proxy;
  own.sphere = {{0, 0, 0}, 1.0f};
  proxy.kind = package::NodeKind::hlod_proxy;
  proxy.objects = {0, 1, 3};
  proxy.sphere = {{0, 0, -15}, 10.0f};
  struct Nodes : NodeSource {
    std::vector<package::NodeRecord> r;
    const package::NodeRecord* record(uint32_t id) const override { return &r.at(id); }
    bool available(uint32_t) const override { return true; }
  } nodes;
  nodes.r = {own, own, proxy};
  package::PackageScene scene;
  package::Representation rep;
  rep.bounds.add(glm::vec3(-1.0f / std::sqrt(3.0f)));
  rep.bounds.add(glm::vec3(1.0f / std::sqrt(3.0f)));
  scene.representations = {rep};
  for (float z : {-10.0f, -20.0f, -12.0f, 30.0f})
    scene.objects.push_back({"o", glm::translate(glm::mat4(1.0f), glm::vec3(2, 0, z)), 0});
  View v = test_view();
  std::vector<double> a;
  for (uint32_t o = 0; o < 3; ++o) a.push_back(projected_area(object_sphere(scene, o), v));
  Cut cut;
  cut.objects = {ObjectState::drawn, ObjectState::drawn, ObjectState::drawn, ObjectState::culled};
  cut.drawn = {{2, 0, 0.5, 10}, {package::kNone, 2, 4.0, 100}};
  const FrameQuality q = frame_quality(scene, nodes, cut, v, 1.0);
  EXPECT_EQ(q.visible_objects, 3u);
  EXPECT_NEAR(q.benefit_ratio, (0.25 * a[0] + 0.25 * a[1] + a[2]) / (a[0] + a[1] + a[2]), 1e-12);
  EXPECT_DOUBLE_EQ(q.pixel_error_max, 4.0);
  EXPECT_DOUBLE_EQ(q.pixel_error_mean, (4.0 + 4.0 + 0.5) / 3.0);
}
