#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.hpp"
#include "measure/surface_distance.hpp"
#include "support/shapes.hpp"

using namespace lodstream;

TEST(SurfaceDistance, MeshAgainstItselfIsZero) {
  Mesh m = test::sphere(1.0f, 24, 48);
  SurfaceDistance d = measure_surface_distance(m, m);
  // Samples are interpolated in float: they lie on the surface up to rounding.
  EXPECT_LT(d.hausdorff, 1e-6);
  EXPECT_LT(d.mean, 1e-7);
  EXPECT_LT(d.rms, 1e-7);
  EXPECT_NEAR(d.a_to_b.area, d.b_to_a.area, 1e-9);
}

TEST(SurfaceDistance, ShiftedPlaneIsTheShift) {
  // Every point of either plane is exactly d from the other (along the normal; both cover [0,1]^2).
  const float d = 0.037f;
  SurfaceDistance r = measure_surface_distance(test::grid(16, 0.0f), test::grid(9, d));
  EXPECT_NEAR(r.hausdorff, d, 1e-6);
  EXPECT_NEAR(r.a_to_b.max, d, 1e-6);
  EXPECT_NEAR(r.b_to_a.max, d, 1e-6);
  EXPECT_NEAR(r.mean, d, 1e-6);
  EXPECT_NEAR(r.rms, d, 1e-6);
}

TEST(SurfaceDistance, ConcentricSpheres) {
  // Same tessellation scaled by 1.1: each triangle of A faces its scaled copy at 0.1·(its distance from the
  // centre), which lies in [cos(π/24)·1, 1] for this tessellation, so every distance is 0.1 within 1e-3.
  SurfaceDistance same = measure_surface_distance(test::sphere(1.0f, 48, 96), test::sphere(1.1f, 48, 96));
  EXPECT_NEAR(same.hausdorff, 0.1, 1e-3);
  EXPECT_NEAR(same.mean, 0.1, 1e-3);
  EXPECT_NEAR(same.rms, 0.1, 1e-3);
  // Different tessellations: the chordal error of each is below r·(1 − cos(π/segments)) ≈ 1.3e-3 (r = 1.1,
  // 64 segments), so the distances are 0.1 within that (inscribed polyhedra: the gap is 0.1 ± 1.3e-3).
  SurfaceDistance mixed = measure_surface_distance(test::sphere(1.0f, 48, 96), test::sphere(1.1f, 32, 64));
  EXPECT_NEAR(mixed.hausdorff, 0.1, 2e-3);
  EXPECT_NEAR(mixed.mean, 0.1, 2e-3);
  EXPECT_NEAR(mixed.rms, 0.1, 2e-3);
}

TEST(SurfaceDistance, OneSidedAsymmetryCatchesASmallFarTriangle) {
  // B = A plus one tiny triangle (area 5e-5, 0.02% of B) 5 units above the plane: every point of A is on B
  // (a→b = 0) but B's extra triangle is 5 away from A (b→a = 5). Its share of B's area samples is ~0; it is
  // caught by its vertices and its guaranteed sample.
  Mesh a = test::grid(8);
  Mesh b = a;
  uint32_t base = uint32_t(b.positions.size());
  b.positions.insert(b.positions.end(), {{0.5f, 0.5f, 5}, {0.51f, 0.5f, 5}, {0.5f, 0.51f, 5}});
  b.normals.insert(b.normals.end(), 3, glm::vec3(0, 0, 1));
  b.indices.insert(b.indices.end(), {base, base + 1, base + 2});
  SurfaceDistance r = measure_surface_distance(a, b);
  EXPECT_LT(r.a_to_b.max, 1e-6);
  EXPECT_NEAR(r.b_to_a.max, 5.0, 1e-5);
  EXPECT_NEAR(r.hausdorff, 5.0, 1e-5);
  // The mean sees the triangle only in proportion to its area: 5 · 5e-5 / (2·1.00005) ≈ 1.25e-4.
  EXPECT_NEAR(r.mean, 5.0 * 5e-5 / (2.0 + 5e-5), 1e-6);
}

TEST(SurfaceDistance, ScenesAreMeasuredInWorldSpace) {
  // A: the unit grid placed at z = 0.2 by its transform, and an instance of it at z = 1.2. B: planes at z = 0
  // and 1.
  Scene a = make_scene(test::grid(4));
  a.objects[0].transform = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 0.2f));
  a.objects.push_back(Object{"copy", glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 1.2f)), 0});
  Scene b = make_scene(test::grid(6, 0.0f));
  b.meshes.push_back(test::grid(3, 1.0f));
  b.objects.push_back(Object{"upper", glm::mat4(1.0f), 1});
  SurfaceDistance r = measure_surface_distance(a, b);
  EXPECT_NEAR(r.hausdorff, 0.2, 1e-6);
  EXPECT_NEAR(r.mean, 0.2, 1e-6);
  EXPECT_NEAR(r.a_to_b.area, 2.0, 1e-6);  // both instances count
}

TEST(SurfaceDistance, SampleCountsAndDeterminism) {
  Mesh a = test::sphere(1.0f, 16, 32), b = test::sphere(1.05f, 20, 40);
  SurfaceDistance r1 = measure_surface_distance(a, b, {5000, 9});
  SurfaceDistance r2 = measure_surface_distance(a, b, {5000, 9});
  EXPECT_EQ(r1.hausdorff, r2.hausdorff);
  EXPECT_EQ(r1.mean, r2.mean);
  EXPECT_EQ(r1.rms, r2.rms);
  // Every vertex plus about N area samples on each side.
  EXPECT_GE(r1.a_to_b.samples, a.vertex_count() + 5000);
  EXPECT_LE(r1.a_to_b.samples, a.vertex_count() + 5000 + a.triangle_count());
  EXPECT_EQ(r1.samples, r1.a_to_b.samples + r1.b_to_a.samples);
  // The default samples at least 100,000 points a side.
  EXPECT_GE(measure_surface_distance(a, b).b_to_a.samples, 100000u + b.vertex_count());
}

TEST(SurfaceDistance, EmptySurfaceIsAnError) {
  EXPECT_THROW(measure_surface_distance(Mesh{}, test::grid(2)), Error);
  EXPECT_THROW(measure_surface_distance(test::grid(2), Mesh{}), Error);
  EXPECT_THROW(measure_surface_distance(Scene{}, make_scene(test::grid(2))), Error);
}
