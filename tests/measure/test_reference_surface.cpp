#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <random>

#include "core/error.hpp"
#include "measure/closest_point.hpp"
#include "measure/reference_surface.hpp"
#include "measure/surface_sampling.hpp"
#include "support/shapes.hpp"

using namespace lodstream;

namespace {
float brute_force_distance(const Mesh& m, const glm::vec3& p) {
  float best = std::numeric_limits<float>::max();
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const uint32_t* v = &m.indices[3 * t];
    glm::vec3 q = closest_point_on_triangle(p, m.positions[v[0]], m.positions[v[1]], m.positions[v[2]]);
    best = std::min(best, glm::length(p - q));
  }
  return best;
}
}  // namespace

TEST(ReferenceSurface, ClosestMatchesBruteForce) {
  Mesh m = test::cube_with_seams(3);
  ReferenceSurface ref(m);
  EXPECT_EQ(ref.triangle_count(), m.triangle_count());
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  std::vector<glm::vec3> points;
  for (int i = 0; i < 500; ++i) points.push_back({u(rng), u(rng), u(rng)});
  std::vector<float> batch(points.size());
  ref.distances(points, batch);
  for (size_t i = 0; i < points.size(); ++i) {
    const float expected = brute_force_distance(m, points[i]);
    ReferenceSurface::Closest c = ref.closest(points[i]);
    EXPECT_NEAR(c.distance, expected, 1e-5f) << "point " << i;
    EXPECT_NEAR(glm::length(points[i] - c.point), c.distance, 1e-5f);
    EXPECT_NEAR(batch[i], expected, 1e-5f) << "point " << i;
  }
}

TEST(ReferenceSurface, AppliesTheTransform) {
  Mesh m = test::grid(4);
  ReferenceSurface ref(m, glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 2)));
  EXPECT_FLOAT_EQ(ref.bounds().min.z, 2.0f);
  EXPECT_NEAR(ref.closest({0.5f, 0.5f, 0}).distance, 2.0f, 1e-6f);
}

TEST(ReferenceSurface, ReusedForManySurfaces) {
  // One reference, several measured surfaces: planes at increasing height above the unit grid.
  ReferenceSurface ref(test::grid(8));
  for (float d : {0.0f, 0.01f, 0.5f}) {
    OneSidedDistance r = ref.distance_from(test::grid(5, d), {20000, 1});
    EXPECT_NEAR(r.max, d, 1e-6);
    EXPECT_NEAR(r.mean, d, 1e-6);
    EXPECT_NEAR(r.rms, d, 1e-6);
    EXPECT_NEAR(r.area, 1.0, 1e-6);
  }
}

TEST(ReferenceSurface, UnreferencedVerticesAreNotSamples) {
  Mesh m = test::grid(4);
  m.positions.push_back({0, 0, 100});  // referenced by no triangle
  OneSidedDistance r = ReferenceSurface(test::grid(4)).distance_from(m, {1000, 1});
  EXPECT_LT(r.max, 1e-6);
  EXPECT_EQ(r.samples, 25u + SurfaceSampler(m, 1000, 1).total_samples());
}

TEST(ReferenceSurface, BadGeometryIsAnError) {
  EXPECT_THROW(ReferenceSurface(Mesh{}), Error);
  Mesh out_of_range = test::grid(2);
  out_of_range.indices[4] = 1000;
  EXPECT_THROW(ReferenceSurface{out_of_range}, Error);
  Mesh nan = test::grid(2);
  nan.positions[0].x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(ReferenceSurface{nan}, Error);
  ReferenceSurface ref(test::grid(2));
  EXPECT_THROW(ref.distance_from(Mesh{}), Error);
  EXPECT_THROW(ref.distance_from(out_of_range), Error);
  EXPECT_THROW(ref.distance_from(nan), Error);
  std::vector<glm::vec3> points(3);
  std::vector<float> out(2);
  EXPECT_THROW(ref.distances(points, out), Error);
}
