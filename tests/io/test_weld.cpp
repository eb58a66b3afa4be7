// Welding: seams stay seams, unwelded and flat-shaded input is welded with crease normals.
#include <gtest/gtest.h>

#include <map>
#include <tuple>

#include "files.hpp"
#include "io/export.hpp"
#include "io/weld.hpp"
#include "support/shapes.hpp"

using namespace lodstream;
using namespace lodstream::test;

namespace {

// Every triangle with its own three vertices; each keeps the face's normal (flat shading) or none.
Mesh unweld(const Mesh& m, bool flat_normals) {
  Mesh out;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    glm::vec3 p[3];
    for (int k = 0; k < 3; ++k) p[k] = m.positions[m.indices[3 * t + k]];
    glm::vec3 n = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
    for (int k = 0; k < 3; ++k) {
      out.indices.push_back(static_cast<uint32_t>(out.positions.size()));
      out.positions.push_back(p[k]);
      if (flat_normals) out.normals.push_back(n);
    }
  }
  return out;
}

}  // namespace

TEST(Weld, IdenticalVerticesMergeAndSeamsStay) {
  Mesh m = uv_sphere(1.0f, 8, 16);
  const size_t vertices = m.vertex_count();
  Mesh u = unweld(m, false);
  // Put back the smooth normals and UVs per corner: welding must restore the shared vertices exactly.
  u.normals.clear();
  for (uint32_t i : m.indices) u.normals.push_back(m.normals[i]), u.uvs.push_back(m.uvs[i]);
  WeldResult r = weld(u, 60.0f);
  EXPECT_FALSE(r.normals_recomputed);
  EXPECT_EQ(u.vertex_count(), vertices);  // the UV seam's duplicated positions stay
  EXPECT_EQ(u.triangle_count(), m.triangle_count());
}

TEST(Weld, FlatShadedCubeKeepsItsCreases) {
  // 120 subdivisions: 87,846 positions, grouped in several runs on several cores.
  for (int subdivisions : {1, 3, 120}) {
    Mesh cube = cube_with_seams(subdivisions);
    Mesh u = unweld(cube, true);
    // Rank of each position by its first use in the unwelded triangles.
    std::map<std::tuple<float, float, float>, size_t> first_use;
    for (uint32_t i : u.indices) {
      const glm::vec3 p = u.positions[i];
      first_use.emplace(std::make_tuple(p.x, p.y, p.z), first_use.size());
    }
    WeldResult r = weld(u, 60.0f);
    // Output vertices come in position order (the serial numbering, whatever the threads did).
    size_t previous = 0;
    for (const glm::vec3& p : u.positions) {
      const size_t rank = first_use.at(std::make_tuple(p.x, p.y, p.z));
      EXPECT_GE(rank, previous);
      previous = rank;
    }
    EXPECT_TRUE(r.normals_recomputed);
    // One vertex per face corner-grid point: the 90-degree edges are creases, faces are flat.
    EXPECT_EQ(u.vertex_count(), cube.vertex_count());
    for (size_t t = 0; t < u.triangle_count(); ++t) {
      glm::vec3 n =
          glm::normalize(glm::cross(u.positions[u.indices[3 * t + 1]] - u.positions[u.indices[3 * t]],
                                    u.positions[u.indices[3 * t + 2]] - u.positions[u.indices[3 * t]]));
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(glm::dot(u.normals[u.indices[3 * t + k]], n), 1.0f, 1e-5);
    }
  }
}

TEST(Weld, CreaseAngleAboveNinetyDegreesSmoothsTheCube) {
  Mesh u = unweld(cube_with_seams(1), false);
  weld(u, 100.0f);
  EXPECT_EQ(u.vertex_count(), 8u);
  for (size_t v = 0; v < 8; ++v) EXPECT_NEAR(glm::length(u.normals[v]), 1.0f, 1e-5);
}

TEST(Weld, UnweldedSphereBecomesSmooth) {
  Mesh s = sphere(1.0f, 24, 48);
  for (bool flat : {false, true}) {
    Mesh u = unweld(s, flat);
    ASSERT_EQ(u.vertex_count(), 3 * s.triangle_count());
    weld(u, 60.0f);
    EXPECT_EQ(u.vertex_count(), s.vertex_count());
    EXPECT_EQ(u.triangle_count(), s.triangle_count());
    for (size_t v = 0; v < u.vertex_count(); ++v)
      EXPECT_GT(glm::dot(u.normals[v], glm::normalize(u.positions[v])), 0.99f);
  }
}

TEST(Weld, ImportWeldsAnUnweldedFile) {
  Scene scene = make_scene(unweld(sphere(1.0f, 10, 20), true));
  auto file = temp_dir() / "soup.ply";
  export_scene(scene, file);
  Scene back = import_model(file);
  EXPECT_EQ(back.meshes[0].vertex_count(), sphere(1.0f, 10, 20).vertex_count());
}
