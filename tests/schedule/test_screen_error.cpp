#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "schedule/screen_error.hpp"

using namespace lodstream;
using namespace lodstream::schedule;

namespace {
Camera camera_at_origin_looking_down_z() {
  Camera c;
  c.eye = {0, 0, 0};
  c.target = {0, 0, -1};
  c.fov_y_degrees = 90.0f;  // tan(45°) = 1
  c.width = 200;
  c.height = 100;
  return c;
}
}  // namespace

TEST(ScreenError, FormulaAtHandComputedDistances) {
  View v = View::of(camera_at_origin_looking_down_z());
  EXPECT_NEAR(v.focal_pixels(), 50.0, 1e-9);  // H / (2 tan 45°)
  // Sphere at distance 10, radius 2: d = 8; e_px = 0.4 * 100 / (2 * 8 * 1) = 2.5.
  WorldSphere s{{0, 0, -10}, 2.0};
  EXPECT_DOUBLE_EQ(sphere_distance(s, v), 8.0);
  EXPECT_NEAR(screen_error(0.4, s, v), 2.5, 1e-12);
  EXPECT_TRUE(std::isinf(screen_error(INFINITY, s, v)));
  // Eye inside the sphere: d clamps to min_distance.
  WorldSphere around{{0, 0, -1}, 5.0};
  EXPECT_DOUBLE_EQ(sphere_distance(around, v), v.min_distance);
  EXPECT_NEAR(screen_error(1e-6, around, v), 50.0, 1e-9);
}

TEST(ScreenError, TransformMovesAndScalesByLargestAxis) {
  glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -20));
  m = glm::scale(m, glm::vec3(1.0f, 3.0f, 2.0f));
  EXPECT_NEAR(max_scale(m), 3.0, 1e-12);
  WorldSphere w = to_world(Sphere{{0, 1, 0}, 1.0f}, m, max_scale(m));
  EXPECT_NEAR(w.center.y, 3.0, 1e-12);
  EXPECT_NEAR(w.center.z, -20.0, 1e-12);
  EXPECT_NEAR(w.radius, 3.0, 1e-12);
}

TEST(ScreenError, MonotonicForContainingSpheresAndLargerErrors) {
  View v = View::of(camera_at_origin_looking_down_z());
  WorldSphere child{{1, 0, -5}, 0.5}, parent{{1.5, 0, -5}, 1.2};  // parent contains child
  for (double z = -30; z <= 3; z += 0.25) {
    v.eye = {0.3, 0.2, z};
    EXPECT_LE(screen_error(0.1, child, v), screen_error(0.1, parent, v));
  }
}

TEST(ScreenError, FrustumCullsSpheresOutsideTheSidePlanesAndBehind) {
  View v = View::of(camera_at_origin_looking_down_z());  // 90° vertical, tan_half_x = 2
  EXPECT_TRUE(in_frustum({{0, 0, -10}, 1}, v));
  EXPECT_FALSE(in_frustum({{0, 0, 10}, 1}, v));   // behind
  EXPECT_TRUE(in_frustum({{0, 0, 0.5}, 1}, v));   // around the eye
  EXPECT_TRUE(in_frustum({{19, 0, -10}, 1}, v));  // inside: |x| <= 2 z
  EXPECT_FALSE(in_frustum({{25, 0, -10}, 1}, v));
  EXPECT_TRUE(in_frustum({{21, 0, -10}, 1}, v));   // touches the plane: 21 - 20 = 1 < r * sqrt(5)
  EXPECT_FALSE(in_frustum({{0, 12, -10}, 1}, v));  // above: |y| <= z
  EXPECT_TRUE(in_frustum({{0, 10.5, -10}, 1}, v));
}
