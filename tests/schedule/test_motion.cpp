#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "schedule/motion.hpp"

using namespace lodstream::schedule;

namespace {
void expect_near(const glm::dvec3& a, const glm::dvec3& b, double tolerance = 1e-12) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}
}  // namespace

TEST(Motion, AStillCameraPredictsItself) {
  ViewSample s;
  s.eye = {1, 2, 3};
  s.forward = {0, 0, -1};
  const ViewSample p = predict(s, 5.0);
  expect_near(p.eye, s.eye);
  expect_near(p.forward, s.forward);
  expect_near(p.up, s.up);
  EXPECT_DOUBLE_EQ(p.time_s, 5.0);
  auto views = predicted_views(s, 0.1);
  ASSERT_EQ(views.size(), 1u);
  EXPECT_DOUBLE_EQ(views[0].weight, 1.0);
}

TEST(Motion, StraightLineMovesTheEyeByVelocityTimesHorizon) {
  ViewSample s;
  s.eye = {1, 0, 0};
  s.velocity = {2, 0, -1};
  const ViewSample p = predict(s, 1.5);
  expect_near(p.eye, {4, 0, -1.5});
  expect_near(p.forward, s.forward);  // no turn
}

TEST(Motion, TurningRotatesForwardAboutTheAxis) {
  // A quarter turn per second about +Y: looking down -Z, after 1 s the camera looks down -X (right-handed:
  // +90 degrees about +Y takes -Z to -X).
  ViewSample s;
  s.forward = {0, 0, -1};
  s.angular_velocity = {0, std::numbers::pi / 2, 0};
  const ViewSample p = predict(s, 1.0);
  expect_near(p.forward, {-1, 0, 0});
  expect_near(p.up, {0, 1, 0});
  expect_near(p.eye, s.eye);
  // Half a second: halfway, at 45 degrees.
  const double h = std::sqrt(0.5);
  expect_near(predict(s, 0.5).forward, {-h, 0, -h});
  // Rolling about the view direction turns up, not forward.
  ViewSample roll = s;
  roll.angular_velocity = {0, 0, -std::numbers::pi / 2};  // about forward (-Z), a quarter per second
  const ViewSample r = predict(roll, 1.0);
  expect_near(r.forward, {0, 0, -1});
  expect_near(r.up, {1, 0, 0});
}

TEST(Motion, ViewOfASampleIsOrthonormalWithThePinholeScale) {
  ViewSample s;
  s.forward = {0, 0, -2};  // not unit
  s.up = {0, 1, 0.5};      // not orthogonal
  s.fov_y_radians = std::numbers::pi / 2;
  s.width = 200;
  s.height = 100;
  const View v = view_of(s);
  expect_near(v.forward, {0, 0, -1});
  expect_near(v.right, {1, 0, 0});
  expect_near(v.up, {0, 1, 0});
  EXPECT_NEAR(v.tan_half_y, 1.0, 1e-12);
  EXPECT_NEAR(v.tan_half_x, 2.0, 1e-12);
  EXPECT_NEAR(v.focal_pixels(), 50.0, 1e-9);
}

TEST(Motion, PredictedViewsLookAheadFromTheLeadWithDecayingWeights) {
  ViewSample s;
  s.velocity = {1, 0, 0};
  PredictionHorizons h;
  h.horizons_s = {0.0, 1.0, 2.0};
  h.decay_s = 1.0;
  auto views = predicted_views(s, 0.5, h);
  ASSERT_EQ(views.size(), 3u);
  EXPECT_NEAR(views[0].view.eye.x, 0.5, 1e-12);
  EXPECT_NEAR(views[1].view.eye.x, 1.5, 1e-12);
  EXPECT_NEAR(views[2].view.eye.x, 2.5, 1e-12);
  EXPECT_DOUBLE_EQ(views[0].weight, 1.0);
  EXPECT_NEAR(views[1].weight, std::exp(-1.0), 1e-12);
  EXPECT_GT(views[1].weight, views[2].weight);
}
