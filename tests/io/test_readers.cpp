// PLY (ascii, binary little and big endian), OFF and OBJ readers, through import_model.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>

#include "files.hpp"
#include "io/export.hpp"
#include "support/shapes.hpp"

using namespace lodstream;
using namespace lodstream::test;

namespace {

template <class T>
void put_be(std::string& out, T value) {
  auto bytes = std::bit_cast<std::array<char, sizeof(T)>>(value);
  for (size_t i = sizeof(T); i-- > 0;) out.push_back(bytes[i]);
}

// A unit square in z = 0 as one quad with per-vertex colours and UVs.
const float kSquare[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

void expect_square(const Scene& s) {
  ASSERT_EQ(s.objects.size(), 1u);
  const Mesh& m = s.meshes[0];
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(m.vertex_count(), 4u);
  ASSERT_TRUE(m.has_colors());
  ASSERT_TRUE(m.has_uvs());
  ASSERT_TRUE(m.has_normals());
  for (size_t v = 0; v < 4; ++v) {
    // Vertex order may change in welding: find each input corner by position.
    glm::vec2 p(m.positions[v]);
    int k = -1;
    for (int i = 0; i < 4; ++i)
      if (p == glm::vec2(kSquare[i][0], kSquare[i][1])) k = i;
    ASSERT_GE(k, 0);
    EXPECT_EQ(m.uvs[v], glm::vec2(kSquare[k][0], kSquare[k][1]));
    EXPECT_NEAR(m.colors[v].r, k * 50 / 255.0f, 1e-6);
    EXPECT_NEAR(m.colors[v].a, 1.0f, 1e-6);
    EXPECT_NEAR(m.normals[v].z, 1.0f, 1e-6);  // recomputed: the file has none
  }
}

}  // namespace

TEST(Ply, AsciiQuadWithColorsAndUvs) {
  std::string text =
      "ply\nformat ascii 1.0\ncomment a square\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty float s\nproperty float t\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 4; ++i)
    text += std::to_string(kSquare[i][0]) + " " + std::to_string(kSquare[i][1]) + " 0 " +
            std::to_string(kSquare[i][0]) + " " + std::to_string(kSquare[i][1]) + " " +
            std::to_string(i * 50) + " 0 0\n";
  text += "4 0 1 2 3\n";
  expect_square(import_model(write_file("square_ascii.ply", text)));
}

TEST(Ply, BinaryBigEndianWithDoublesAndExtraProperties) {
  std::string b =
      "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
      "property double z\nproperty float confidence\nproperty float u\nproperty float v\nproperty uchar red\n"
      "property uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar uint vertex_indices\n"
      "property uchar flags\nend_header\n";
  for (int i = 0; i < 4; ++i) {
    put_be(b, double(kSquare[i][0]));
    put_be(b, double(kSquare[i][1]));
    put_be(b, 0.0);
    put_be(b, 0.5f);
    put_be(b, kSquare[i][0]);
    put_be(b, kSquare[i][1]);
    b += char(i * 50), b += char(0), b += char(0);
  }
  b += char(4);
  for (uint32_t i = 0; i < 4; ++i) put_be(b, i);
  b += char(7);
  expect_square(import_model(write_file("square_be.ply", b)));
}

TEST(Ply, RoundTripThroughExport) {
  Mesh m = uv_sphere(2.0f, 12, 24);
  m.colors.resize(m.positions.size());
  for (size_t i = 0; i < m.colors.size(); ++i) m.colors[i] = glm::vec4((i % 7) / 255.0f, 1.0f, 0.0f, 1.0f);
  Scene scene = make_scene(m, "ball");
  scene.objects[0].transform = glm::mat4(1.0f);
  scene.objects[0].transform[3] = glm::vec4(10, 0, 0, 1);  // translated: export applies it
  auto file = temp_dir() / "ball.ply";
  export_scene(scene, file);
  Scene back = import_model(file);
  ASSERT_EQ(back.meshes.size(), 1u);
  const Mesh& r = back.meshes[0];
  EXPECT_EQ(r.triangle_count(), m.triangle_count());
  EXPECT_EQ(r.vertex_count(), m.vertex_count());  // the UV seam stays a seam
  EXPECT_TRUE(r.has_normals() && r.has_uvs() && r.has_colors());
  Bounds b = back.bounds();
  EXPECT_NEAR(b.min.x, 8.0f, 1e-5);
  EXPECT_NEAR(b.max.x, 12.0f, 1e-5);
  // Every triangle comes back with the same corner positions and UVs, in order.
  for (size_t t = 0; t < m.indices.size(); ++t) {
    EXPECT_EQ(r.positions[r.indices[t]], m.positions[m.indices[t]] + glm::vec3(10, 0, 0));
    EXPECT_EQ(r.uvs[r.indices[t]], m.uvs[m.indices[t]]);
    EXPECT_NEAR(r.colors[r.indices[t]].r, m.colors[m.indices[t]].r, 1e-6);
    EXPECT_NEAR(glm::dot(r.normals[r.indices[t]], m.normals[m.indices[t]]), 1.0f, 1e-5);
  }
}

// Binary little-endian PLY of `m` (positions only), its faces as triangles plus, when `quad`, one quad at
// the end; the faces are read in parallel at their stride unless some face is not a triangle.
std::string binary_ply(const Mesh& m, bool quad) {
  std::string b = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(m.vertex_count()) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(m.triangle_count() + quad) +
                  "\nproperty list uchar int vertex_indices\nend_header\n";
  b.append(reinterpret_cast<const char*>(m.positions.data()), m.positions.size() * sizeof(glm::vec3));
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    b += char(3);
    b.append(reinterpret_cast<const char*>(&m.indices[3 * t]), 3 * sizeof(uint32_t));
  }
  if (quad) {
    const int32_t corners[4] = {0, 1, 2, 3};
    b += char(4);
    b.append(reinterpret_cast<const char*>(corners), sizeof corners);
  }
  return b;
}

TEST(Ply, LargeBinaryTrianglesInOrderWithOrWithoutAPolygon) {
  const Mesh m = sphere(1.0f, 150, 300);  // 89,400 triangles: several parallel runs
  for (bool quad : {false, true}) {
    Scene back = import_model(write_file(quad ? "big_quad.ply" : "big.ply", binary_ply(m, quad)));
    const Mesh& r = back.meshes[0];
    ASSERT_EQ(r.triangle_count(), m.triangle_count() + 2 * quad);
    for (size_t t = 0; t < m.indices.size(); ++t)
      ASSERT_EQ(r.positions[r.indices[t]], m.positions[m.indices[t]]);
  }
  std::string bad = binary_ply(m, false);
  const size_t last_index = bad.size() - sizeof(int32_t);
  const int32_t out_of_range = int32_t(m.vertex_count());
  std::memcpy(&bad[last_index], &out_of_range, sizeof out_of_range);
  EXPECT_NE(
      import_error(write_file("big_bad.ply", bad)).find("face " + std::to_string(m.triangle_count() - 1)),
      std::string::npos);
}

TEST(Off, PolygonsCommentsAndCountsOnTheKeywordLine) {
  // A pyramid: square base (one quad) and four triangles; a pentagon elsewhere (fan of 3).
  auto file = write_file("pyramid.off",
                         "OFF 10 6 0 # counts here\n# a comment line\n\n"
                         "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n"
                         "5 0 0\n6 0 0\n6.5 1 0\n5.5 2 0\n4.5 1 0\n"
                         "4 3 2 1 0\n3 0 1 4\n3 1 2 4 255 0 0\n3 2 3 4\n3 3 0 4\n5 5 6 7 8 9\n");
  Scene s = import_model(file);
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].triangle_count(), 2u + 4u + 3u);
  EXPECT_EQ(s.objects[0].name, "pyramid");
  EXPECT_EQ(s.bounds().max, glm::vec3(6.5f, 2.0f, 1.0f));
}

TEST(Off, ColorOff) {
  auto file =
      write_file("c.off", "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n");
  Scene s = import_model(file);
  ASSERT_TRUE(s.meshes[0].has_colors());
  glm::vec4 sum(0.0f);
  for (auto& c : s.meshes[0].colors) sum += c;
  EXPECT_EQ(sum, glm::vec4(1, 1, 1, 3));
}

TEST(Obj, GroupsMaterialsTexturesAndRoundTrip) {
  auto dir = temp_dir();
  {
    std::ofstream(dir / "m.mtl")
        << "newmtl red\nKd 1 0 0\nnewmtl tex\nKd 0.5 0.5 0.5\nd 0.5\nmap_Kd img/wood.png\n";
    std::ofstream(dir / "two.obj")
        << "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\n"
           "vt 1 1\nvt 0 1\ng first\nusemtl red\nf 1 2 3 4\nusemtl tex\n"
           "f 1/1 2/2 5/3\ng second\nusemtl red\nf 2 3 5\n";
  }
  Scene s = import_model(dir / "two.obj");
  ASSERT_EQ(s.objects.size(), 3u);  // first/red, first/tex, second
  EXPECT_EQ(s.objects[0].name, "first/red");
  EXPECT_EQ(s.objects[1].name, "first/tex");
  EXPECT_EQ(s.objects[2].name, "second");
  EXPECT_EQ(s.triangle_count(), 4u);
  const Material& tex = s.materials[s.meshes[s.objects[1].mesh].material];
  EXPECT_EQ(tex.name, "tex");
  EXPECT_EQ(tex.base_color, glm::vec4(0.5f, 0.5f, 0.5f, 0.5f));
  EXPECT_EQ(tex.base_color_texture, (dir / "img" / "wood.png").lexically_normal().string());
  EXPECT_EQ(s.materials[s.meshes[s.objects[0].mesh].material].base_color, glm::vec4(1, 0, 0, 1));
  EXPECT_TRUE(s.meshes[s.objects[1].mesh].has_uvs());

  export_scene(s, dir / "again.obj");
  Scene back = import_model(dir / "again.obj");
  ASSERT_EQ(back.objects.size(), s.objects.size());
  EXPECT_EQ(back.triangle_count(), s.triangle_count());
  EXPECT_EQ(back.bounds().min, s.bounds().min);
  EXPECT_EQ(back.bounds().max, s.bounds().max);
  bool found_texture = false;
  for (const auto& m : back.materials) found_texture |= m.base_color_texture == tex.base_color_texture;
  EXPECT_TRUE(found_texture);
}

TEST(Export, InstancesAreExpanded) {
  Scene s = make_scene(sphere(1.0f, 6, 8), "a");
  Object b = s.objects[0];
  b.name = "b";
  b.transform[3] = glm::vec4(5, 0, 0, 1);
  s.objects.push_back(b);
  EXPECT_EQ(s.unique_triangle_count() * 2, s.triangle_count());
  auto file = temp_dir() / "two.ply";
  export_scene(s, file);
  Scene back = import_model(file);
  EXPECT_EQ(back.triangle_count(), s.triangle_count());
  EXPECT_NEAR(back.bounds().max.x, 6.0f, 1e-6);
  EXPECT_THROW(export_scene(s, temp_dir() / "x.stl"), Error);
}
