#include <gtest/gtest.h>

#include <random>

#include "measure/closest_point.hpp"

using namespace lodstream;

namespace {
// Closest point found by brute force over a dense barycentric grid of the triangle (spacing 1/n of each
// edge).
float brute_force_distance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                           int n) {
  float best = std::numeric_limits<float>::max();
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      glm::vec3 q = a + (float(i) / float(n)) * (b - a) + (float(j) / float(n)) * (c - a);
      best = std::min(best, glm::length(p - q));
    }
  return best;
}
}  // namespace

TEST(ClosestPoint, EveryVoronoiRegion) {
  const glm::vec3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  // Face: straight down onto the plane.
  EXPECT_EQ(closest_point_on_triangle({0.25f, 0.25f, 2}, a, b, c), glm::vec3(0.25f, 0.25f, 0));
  // Vertices.
  EXPECT_EQ(closest_point_on_triangle({-1, -1, 1}, a, b, c), a);
  EXPECT_EQ(closest_point_on_triangle({2, -0.5f, 0}, a, b, c), b);
  EXPECT_EQ(closest_point_on_triangle({-0.5f, 3, 0}, a, b, c), c);
  // Edges AB, AC and BC.
  EXPECT_EQ(closest_point_on_triangle({0.5f, -1, 1}, a, b, c), glm::vec3(0.5f, 0, 0));
  EXPECT_EQ(closest_point_on_triangle({-1, 0.5f, -1}, a, b, c), glm::vec3(0, 0.5f, 0));
  glm::vec3 q = closest_point_on_triangle({1, 1, 0}, a, b, c);
  EXPECT_NEAR(q.x, 0.5f, 1e-6f);
  EXPECT_NEAR(q.y, 0.5f, 1e-6f);
}

TEST(ClosestPoint, MatchesBruteForceOnRandomTriangles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto random_point = [&] { return glm::vec3(u(rng), u(rng), u(rng)); };
  for (int trial = 0; trial < 200; ++trial) {
    glm::vec3 a = random_point(), b = random_point(), c = random_point(), p = 2.0f * random_point();
    float exact = glm::length(p - closest_point_on_triangle(p, a, b, c));
    float brute = brute_force_distance(p, a, b, c, 200);
    // The grid's spacing is at most 2·sqrt(3)/200 ≈ 0.017: brute force is at most that much above the exact
    // answer.
    EXPECT_LE(exact, brute + 1e-5f) << "trial " << trial;
    EXPECT_GE(exact, brute - 0.02f) << "trial " << trial;
  }
}

TEST(ClosestPoint, DegenerateTrianglesAreSegments) {
  // All three corners on the x axis: a segment from 0 to 2 (with a repeated point).
  const glm::vec3 a{0, 0, 0}, b{2, 0, 0}, c{1, 0, 0};
  EXPECT_EQ(closest_point_on_triangle({1.5f, 3, 0}, a, b, c), glm::vec3(1.5f, 0, 0));
  EXPECT_EQ(closest_point_on_triangle({5, 1, 0}, a, b, c), b);
  // All three corners at one point.
  EXPECT_EQ(closest_point_on_triangle({1, 1, 1}, c, c, c), c);
}

TEST(ClosestPoint, LongThinTrianglesFarFromTheOriginStayExact) {
  // Slivers like the facades of buildings.obj (200 units long, a few millimetres wide, far from the origin):
  // points on them are at distance ~0 from them.
  glm::vec3 a{30.0f, 150.0f, 10.0f}, b{237.0f, 158.0f, 76.0f};
  for (float width : {1e-1f, 1e-2f, 1e-3f})
    for (int i = 1; i < 100; ++i) {
      glm::vec3 c = 0.5f * (a + b) + glm::vec3(0.0f, 0.0f, width);
      float u = float(i) / 100.0f, v = 0.5f * (1.0f - u);
      glm::vec3 p = a + u * (b - a) + v * (c - a);
      EXPECT_LT(glm::length(closest_point_on_triangle(p, a, b, c) - p), 1e-4f)
          << "width " << width << ", u " << u;
    }
}
