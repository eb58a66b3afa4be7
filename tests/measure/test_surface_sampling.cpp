#include <gtest/gtest.h>

#include "measure/surface_sampling.hpp"
#include "support/shapes.hpp"

using namespace lodstream;

namespace {
// Two triangles in the z = 0 plane with areas 1 and 3.
Mesh two_triangles() {
  Mesh m;
  m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 1, 0}, {10, 0, 0}, {13, 0, 0}, {10, 2, 0}};
  m.indices = {0, 1, 2, 3, 4, 5};
  return m;
}
}  // namespace

TEST(SurfaceSampling, CountsFollowAreaAndEveryTriangleGetsOne) {
  Mesh m = two_triangles();
  SurfaceSampler s(m, 1000, 1);
  EXPECT_DOUBLE_EQ(s.total_area(), 4.0);
  // Systematic sampling gives each triangle the floor or ceiling of its share N·A_t/A.
  EXPECT_GE(s.sample_count(0), 249u);
  EXPECT_LE(s.sample_count(0), 251u);
  EXPECT_GE(s.sample_count(1), 749u);
  EXPECT_LE(s.sample_count(1), 751u);
  EXPECT_EQ(s.total_samples(), s.sample_count(0) + s.sample_count(1));
  // Far fewer samples than triangles: still one for each.
  Mesh fine = test::sphere(1.0f, 32, 64);
  SurfaceSampler sparse(fine, 10, 1);
  for (size_t t = 0; t < fine.triangle_count(); ++t)
    ASSERT_EQ(sparse.sample_count(t), 1u) << "triangle " << t;
  EXPECT_EQ(sparse.total_samples(), fine.triangle_count());
}

TEST(SurfaceSampling, SamplesLieInTheirTriangleAndCoverIt) {
  Mesh m = two_triangles();
  SurfaceSampler s(m, 4000, 3);
  std::vector<glm::vec3> points;
  s.sample_triangle(1, points);  // (10,0) (13,0) (10,2): x >= 10, y >= 0, x/3 + y/2 <= 1 in local coordinates
  ASSERT_EQ(points.size(), s.sample_count(1));
  glm::vec3 mean(0.0f);
  int in_corner = 0;  // samples with local x/3 + y/2 < 0.5: a quarter of the area
  for (const glm::vec3& p : points) {
    float x = p.x - 10.0f, y = p.y;
    EXPECT_GE(x, -1e-5f);
    EXPECT_GE(y, -1e-5f);
    EXPECT_LE(x / 3.0f + y / 2.0f, 1.0f + 1e-5f);
    EXPECT_EQ(p.z, 0.0f);
    mean += p;
    if (x / 3.0f + y / 2.0f < 0.5f) ++in_corner;
  }
  // Uniform density: the mean is the centroid (11, 2/3) and the corner triangle holds a quarter of the
  // points.
  mean /= float(points.size());
  EXPECT_NEAR(mean.x, 11.0f, 0.01f);
  EXPECT_NEAR(mean.y, 2.0f / 3.0f, 0.01f);
  EXPECT_NEAR(double(in_corner) / double(points.size()), 0.25, 0.01);
}

TEST(SurfaceSampling, DeterministicForASeed) {
  Mesh m = test::sphere(1.0f, 8, 16);
  SurfaceSampler a(m, 5000, 42), b(m, 5000, 42), c(m, 5000, 43);
  std::vector<glm::vec3> pa, pb, pc;
  bool any_differs = false;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    a.sample_triangle(t, pa);
    b.sample_triangle(t, pb);
    c.sample_triangle(t, pc);
    ASSERT_EQ(pa, pb) << "triangle " << t;
    if (pa != pc) any_differs = true;
  }
  EXPECT_TRUE(any_differs);
}

TEST(SurfaceSampling, DefaultGrowsWithTriangles) {
  EXPECT_EQ(default_area_samples(10), 100000u);
  EXPECT_EQ(default_area_samples(1000000), 2000000u);
}
