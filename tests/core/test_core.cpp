#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <iterator>

#include "core/camera.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "core/prefault.hpp"
#include "core/representatives.hpp"
#include "core/scene.hpp"
#include "support/run.hpp"
#include "support/shapes.hpp"

using namespace lodstream;

TEST(Bounds, DiagonalAndTransform) {
  Bounds b;
  EXPECT_TRUE(b.empty());
  EXPECT_EQ(b.diagonal(), 0.0f);
  b.add({0, 0, 0});
  b.add({3, 4, 0});
  EXPECT_FLOAT_EQ(b.diagonal(), 5.0f);
  Bounds t = transform_bounds(b, glm::translate(glm::mat4(1.0f), glm::vec3(10, 0, 0)));
  EXPECT_FLOAT_EQ(t.min.x, 10.0f);
  EXPECT_FLOAT_EQ(t.max.x, 13.0f);
}

TEST(Scene, InstancesCountAsDrawn) {
  Scene s = make_scene(test::grid(4));
  s.objects.push_back(Object{"copy", glm::translate(glm::mat4(1.0f), glm::vec3(5, 0, 0)), 0});
  EXPECT_EQ(s.unique_triangle_count(), 32u);
  EXPECT_EQ(s.triangle_count(), 64u);
  EXPECT_FLOAT_EQ(s.bounds().max.x, 6.0f);
}

TEST(Mesh, SmoothNormalsOfSpherePointOutward) {
  Mesh m = test::sphere(2.0f, 16, 32);
  compute_smooth_normals(m);
  for (size_t i = 0; i < m.positions.size(); ++i)
    EXPECT_GT(glm::dot(m.normals[i], glm::normalize(m.positions[i])), 0.99f) << "vertex " << i;
}

TEST(Shapes, CubeHasSeamsAndClosedArea) {
  Mesh m = test::cube_with_seams(2);
  EXPECT_EQ(m.vertex_count(), 6u * 9u);
  EXPECT_EQ(m.triangle_count(), 6u * 8u);
  double area = 0;
  for (size_t t = 0; t < m.triangle_count(); ++t) area += 0.5 * triangle_double_area(m, t);
  EXPECT_NEAR(area, 24.0, 1e-4);
  // Every face normal agrees with the stored (outward) vertex normal.
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const uint32_t* v = &m.indices[3 * t];
    glm::vec3 n = glm::cross(m.positions[v[1]] - m.positions[v[0]], m.positions[v[2]] - m.positions[v[0]]);
    EXPECT_GT(glm::dot(n, m.normals[v[0]]), 0.0f) << "triangle " << t;
  }
}

namespace {
std::filesystem::path write(const std::string& text) {
  auto p = test::temp_dir() / "camera.json";
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST(Camera, LoadsFileWithDefaults) {
  Camera c = load_camera(write(R"({"eye": [0, 1, 5], "target": [0, 1, 0], "size": [640, 480]})"));
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  EXPECT_FLOAT_EQ(c.fov_y_degrees, 60.0f);
  EXPECT_FLOAT_EQ(c.eye.z, 5.0f);
  // The view matrix maps the target onto the negative z axis.
  glm::vec4 t = c.view() * glm::vec4(c.target, 1.0f);
  EXPECT_NEAR(t.x, 0.0f, 1e-6f);
  EXPECT_NEAR(t.z, -5.0f, 1e-5f);
}

TEST(Camera, RejectsBadFilesWithOneLineErrors) {
  for (const char* text :
       {"{", "[]", R"({"eye": [0,0,0]})", R"({"eye": [0,0,0], "target": [0,0,0]})",
        R"({"eye": [0,0,1], "target": [0,0,0], "up": [0,0,1]})",
        R"({"eye": [0,0,1], "target": [0,0,0], "fov": 200})",
        R"({"eye": [0,0,1], "target": [0,0,0], "size": [0, 10]})", R"({"eye": "x", "target": [0,0,0]})"}) {
    try {
      load_camera(write(text));
      ADD_FAILURE() << "accepted " << text;
    } catch (const Error& e) {
      std::string msg = e.what();
      EXPECT_NE(msg.find("camera.json"), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
}

TEST(Image, PngRoundTripIsExactAndDeterministic) {
  Image img(7, 5);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      uint8_t* p = img.pixel(x, y);
      p[0] = uint8_t(x * 30), p[1] = uint8_t(y * 50), p[2] = uint8_t(x * y), p[3] = 255;
    }
  auto dir = test::temp_dir();
  save_png(img, dir / "a.png");
  save_png(img, dir / "b.png");
  Image back = load_image(dir / "a.png");
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  EXPECT_EQ(back.rgba, img.rgba);
  EXPECT_EQ(std::filesystem::file_size(dir / "a.png"), std::filesystem::file_size(dir / "b.png"));
  EXPECT_THROW(load_image(dir / "missing.png"), Error);
  EXPECT_THROW(save_png(img, dir / "no-such-dir" / "c.png"), Error);
}

TEST(Image, DecodesAFileHeldInMemoryAndNamesGarbage) {
  Image img(3, 2);
  for (size_t i = 0; i < img.rgba.size(); ++i) img.rgba[i] = uint8_t(i * 11);
  auto dir = test::temp_dir();
  save_png(img, dir / "a.png");
  std::ifstream in(dir / "a.png", std::ios::binary);
  std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), {}};
  EXPECT_EQ(decode_image(bytes, "mem").rgba, img.rgba);
  bytes.resize(bytes.size() / 2);  // truncated
  try {
    decode_image(bytes, "scene.lods: texture blob 0");
    ADD_FAILURE() << "a truncated PNG decoded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scene.lods: texture blob 0"), std::string::npos) << e.what();
  }
}

TEST(Prefault, KeepsContentsAndLeavesReservedStorageUsable) {
  // Prefaulting a range that starts and ends inside pages (and in the middle of an array) changes no byte,
  // its own or its neighbours'.
  std::vector<uint32_t> filled(3'000'000);
  for (size_t i = 0; i < filled.size(); ++i) filled[i] = uint32_t(i * 2654435761u);
  prefault(filled.data() + 1'001, (filled.size() - 2'003) * sizeof(uint32_t));
  for (size_t i = 0; i < filled.size(); ++i) ASSERT_EQ(filled[i], uint32_t(i * 2654435761u)) << i;
  // What the bake does with it: reserve, prefault, then fill on one thread, as without it.
  std::vector<uint32_t> v;
  reserve_prefaulted(v, 5'000'000);
  EXPECT_TRUE(v.empty());
  EXPECT_GE(v.capacity(), 5'000'000u);
  v.assign(5'000'000, 7u);
  EXPECT_EQ(std::count(v.begin(), v.end(), 7u), 5'000'000);
  std::vector<uint64_t> w;  // resize_prefaulted: sized and filled with the value
  resize_prefaulted(w, 3'000'000, uint64_t(9));
  ASSERT_EQ(w.size(), 3'000'000u);
  EXPECT_EQ(std::count(w.begin(), w.end(), uint64_t(9)), 3'000'000);
  std::vector<uint8_t> small;  // under kPrefaultMinBytes: a plain reserve
  reserve_prefaulted(small, 100);
  EXPECT_GE(small.capacity(), 100u);
}

TEST(Representatives, SmallestEqualItemInOneBucketAndInMany) {
  // Items equal when their values agree; a hash that collides across classes too (its low 32 bits), so the
  // equality decides. 500 items are one bucket (resolved in input order, without the sort), 50,000 many.
  for (const size_t n : {size_t(0), size_t(1), size_t(500), size_t(1023), size_t(50'000)}) {
    std::vector<uint32_t> value(n);
    for (size_t i = 0; i < n; ++i) value[i] = uint32_t((i * 2654435761u) % 97);
    const std::vector<uint32_t> rep = representatives(
        n, [&](size_t i) { return uint64_t(value[i] % 13) * 0x9E3779B97F4A7C15ull; },
        [&](uint32_t a, uint32_t b) { return value[a] == value[b]; });
    ASSERT_EQ(rep.size(), n);
    std::vector<uint32_t> first(97, UINT32_MAX);
    for (size_t i = 0; i < n; ++i) {
      if (first[value[i]] == UINT32_MAX) first[value[i]] = uint32_t(i);
      ASSERT_EQ(rep[i], first[value[i]]) << "n " << n << ", item " << i;
    }
  }
}
