#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.hpp"
#include "core/scene.hpp"
#include "render/depth_range.hpp"
#include "render/renderer.hpp"
#include "render/scene_upload.hpp"
#include "render_fixture.hpp"
#include "support/run.hpp"
#include "support/shapes.hpp"

using namespace lodstream;
using namespace lodstream::render;

namespace {

Image render_once(Renderer& renderer, const Camera& camera, std::span<const DrawItem> items) {
  renderer.draw(camera, items);
  return renderer.read_pixels();
}

// A unit quad in the z = 0 plane facing +z, UV (0,0) at (-1,-1) and (1,1) at (1,1).
Mesh textured_quad() {
  Mesh m;
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  m.normals.assign(4, {0, 0, 1});
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

}  // namespace

TEST(DepthRange, BracketsBoxInFront) {
  Camera c = test::camera_at({0, 0, 10}, {0, 0, 0}, 64, 64);
  Bounds b{{-1, -1, -1}, {1, 1, 1}};
  DepthRange r = depth_range(c, std::span(&b, 1));
  EXPECT_FALSE(r.empty());
  EXPECT_LE(r.near_plane, 9.0f);
  EXPECT_GT(r.near_plane, 8.5f);
  EXPECT_GE(r.far_plane, 11.0f);
  EXPECT_LT(r.far_plane, 11.5f);
}

TEST(DepthRange, EyeInsideClampsNearToFractionOfFar) {
  Camera c = test::camera_at({0, 0, 0}, {0, 0, -1}, 64, 64);
  Bounds b{{-5, -5, -20}, {5, 5, 5}};
  DepthRange r = depth_range(c, std::span(&b, 1));
  EXPECT_FLOAT_EQ(r.far_plane, 1.01f * 20.0f);
  EXPECT_FLOAT_EQ(r.near_plane, r.far_plane / kMaxDepthRatio);
}

TEST(DepthRange, EverythingBehindIsEmpty) {
  Camera c = test::camera_at({0, 0, 5}, {0, 0, 10}, 64, 64);
  Bounds b{{-1, -1, -1}, {1, 1, 1}};
  EXPECT_TRUE(depth_range(c, std::span(&b, 1)).empty());
  EXPECT_TRUE(depth_range(c, {}).empty());
}

// A sphere of radius r at distance d on the optical axis projects to a disc of radius f tan(asin(r/d))
// pixels, f = (H/2) / tan(fov_y/2); the covered area must match pi R^2.
TEST(Renderer, SphereCoversItsProjectedDisc) {
  Renderer renderer(test::headless_context());
  MeshHandle sphere = renderer.upload_mesh(test::sphere(1.0f, 96, 192));
  const float d = 4.0f;
  Camera c = test::camera_at({0, 0, d}, {0, 0, 0}, 256, 256, 60.0f);
  DrawItem item{sphere, glm::mat4(1.0f), {}};
  Image image = render_once(renderer, c, std::span(&item, 1));
  ASSERT_EQ(image.width, 256);
  ASSERT_EQ(image.height, 256);
  const double f = 128.0 / std::tan(glm::radians(30.0));
  const double radius_px = f * std::tan(std::asin(1.0 / d));
  const double expected = glm::pi<double>() * radius_px * radius_px;
  EXPECT_NEAR(double(test::covered_pixels(image)), expected, 0.02 * expected);
  // Background at the corners, lit grey at the centre (normal towards the eye: full Lambert term).
  EXPECT_TRUE(test::is_background(image, 0, 0));
  EXPECT_TRUE(test::is_background(image, 255, 255));
  const uint8_t* centre = image.pixel(128, 128);
  // 0.8 linear grey, sRGB encoded: 1.055 * 0.8^(1/2.4) - 0.055 = 0.906 -> 231.
  EXPECT_NEAR(centre[0], 231, 1);
  EXPECT_EQ(centre[0], centre[1]);
  EXPECT_EQ(centre[1], centre[2]);
  EXPECT_EQ(centre[3], 255);
}

TEST(Renderer, TexturedQuadShowsTextureColours) {
  Renderer renderer(test::headless_context());
  // Four 4x4-texel quadrants, so that filtering at a quadrant's centre mixes only texels of its colour.
  Image texture(8, 8);
  const uint8_t texels[4][4] = {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {255, 255, 255, 255}};
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) std::copy_n(texels[(y / 4) * 2 + x / 4], 4, texture.pixel(x, y));
  DrawItem item{renderer.upload_mesh(textured_quad()),
                glm::mat4(1.0f),
                {{1, 1, 1, 1}, renderer.upload_texture(texture)}};
  Camera c = test::camera_at({0, 0, 3}, {0, 0, 0}, 128, 128);
  Image image = render_once(renderer, c, std::span(&item, 1));
  // Quadrant centres: image row 0 (top) is v = 1, so the top-left quadrant is around (-0.5, 0.5).
  const glm::vec3 centres[4] = {{-0.5f, 0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}};
  for (int i = 0; i < 4; ++i) {
    glm::ivec2 p = test::project_to_pixel(c, centres[i]);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(image.pixel(p.x, p.y)[k], texels[i][k], 2) << "texel " << i << " channel " << k;
  }
  EXPECT_TRUE(test::is_background(image, 2, 2));
}

TEST(Renderer, VertexColoursTintTheBaseColour) {
  Renderer renderer(test::headless_context());
  Mesh quad = textured_quad();
  quad.uvs.clear();
  quad.colors.assign(4, {0.0f, 1.0f, 0.0f, 1.0f});
  DrawItem item{renderer.upload_mesh(quad), glm::mat4(1.0f), {{1, 1, 1, 1}, kNoTexture}};
  Camera c = test::camera_at({0, 0, 3}, {0, 0, 0}, 64, 64);
  Image image = render_once(renderer, c, std::span(&item, 1));
  const uint8_t* p = image.pixel(32, 32);
  EXPECT_EQ(p[0], 0);
  EXPECT_NEAR(p[1], 255, 1);
  EXPECT_EQ(p[2], 0);
}

TEST(Renderer, TranslatedInstanceAppearsWhereItsTransformSays) {
  Renderer renderer(test::headless_context());
  MeshHandle sphere = renderer.upload_mesh(test::sphere(0.5f, 16, 32));
  const glm::vec3 offset{2.5f, 1.0f, 0.0f};
  DrawItem items[2] = {{sphere, glm::mat4(1.0f), {{0.8f, 0.8f, 0.8f, 1}, kNoTexture}},
                       {sphere, glm::translate(glm::mat4(1.0f), offset), {{1, 0, 0, 1}, kNoTexture}}};
  Camera c = test::camera_at({0, 0, 8}, {0, 0, 0}, 160, 120);
  Image image = render_once(renderer, c, items);
  glm::ivec2 at = test::project_to_pixel(c, offset);
  const uint8_t* p = image.pixel(at.x, at.y);
  EXPECT_GT(p[0], 200);
  EXPECT_EQ(p[1], 0);
  EXPECT_EQ(p[2], 0);
  glm::ivec2 mirror = test::project_to_pixel(c, {-offset.x, offset.y, 0});
  EXPECT_TRUE(test::is_background(image, mirror.x, mirror.y));
  glm::ivec2 origin = test::project_to_pixel(c, {0, 0, 0});
  EXPECT_EQ(image.pixel(origin.x, origin.y)[0], image.pixel(origin.x, origin.y)[1]);  // the grey one
}

TEST(Renderer, NearerSurfaceHidesFartherWhateverTheDrawOrder) {
  Renderer renderer(test::headless_context());
  MeshHandle sphere = renderer.upload_mesh(test::sphere(1.0f, 16, 32));
  DrawItem near_red{sphere, glm::mat4(1.0f), {{1, 0, 0, 1}, kNoTexture}};
  DrawItem far_green{sphere,
                     glm::translate(glm::scale(glm::mat4(1.0f), glm::vec3(2.0f)), {0, 0, -2}),
                     {{0, 1, 0, 1}, kNoTexture}};
  Camera c = test::camera_at({0, 0, 5}, {0, 0, 0}, 64, 64);
  for (auto items : {std::vector{near_red, far_green}, std::vector{far_green, near_red}}) {
    Image image = render_once(renderer, c, items);
    EXPECT_GT(image.pixel(32, 32)[0], 200);
    EXPECT_EQ(image.pixel(32, 32)[1], 0);
  }
}

TEST(Renderer, CameraLookingAwayDrawsBackgroundOnly) {
  Renderer renderer(test::headless_context());
  DrawItem item{renderer.upload_mesh(test::sphere()), glm::mat4(1.0f), {}};
  Image image = render_once(renderer, test::camera_at({0, 0, 4}, {0, 0, 8}, 64, 48), std::span(&item, 1));
  EXPECT_EQ(test::covered_pixels(image), 0u);
}

TEST(Renderer, EyeInsideTheBoundsStillDrawsNearbyGeometry) {
  // A 100 x 100 floor with the eye 0.5 above its middle: the floor fills the lower half of the image.
  Renderer renderer(test::headless_context());
  glm::mat4 floor = glm::scale(glm::translate(glm::mat4(1.0f), {-50, 0, 50}), {100, 100, 100}) *
                    glm::rotate(glm::mat4(1.0f), -glm::half_pi<float>(), {1, 0, 0});
  DrawItem item{renderer.upload_mesh(test::grid(8)), floor, {}};
  Image image =
      render_once(renderer, test::camera_at({0, 0.5f, 0}, {0, 0.5f, -1}, 64, 64), std::span(&item, 1));
  for (int y = 40; y < 64; ++y) EXPECT_FALSE(test::is_background(image, 32, y)) << "row " << y;
  EXPECT_TRUE(test::is_background(image, 32, 10));
}

TEST(Renderer, SameInputSameBytes) {
  Scene scene = make_scene(test::sphere(1.0f, 24, 48));
  scene.objects.push_back({"copy", glm::translate(glm::mat4(1.0f), {1.5f, 0.3f, -1}), 0});
  Camera c = test::camera_at({1, 2, 5}, {0.5f, 0, 0}, 96, 64);
  Image first;
  for (int run = 0; run < 2; ++run) {
    Renderer renderer(test::headless_context());
    SceneUpload upload = upload_scene(renderer, scene);
    Image image = render_once(renderer, c, upload.items);
    if (run == 0)
      first = image;
    else
      EXPECT_EQ(image.rgba, first.rgba);
  }
  EXPECT_GT(test::covered_pixels(first), 500u);
}

TEST(SceneUpload, MissingTextureWarnsAndFallsBackToBaseColour) {
  Scene scene = make_scene(textured_quad());
  scene.materials[0].name = "painted";
  scene.materials[0].base_color = {0, 0, 1, 1};
  scene.materials[0].base_color_texture = (test::temp_dir() / "no-such-texture.png").string();
  Renderer renderer(test::headless_context());
  SceneUpload upload = upload_scene(renderer, scene);
  ASSERT_EQ(upload.warnings.size(), 1u);
  EXPECT_NE(upload.warnings[0].find("no-such-texture.png"), std::string::npos) << upload.warnings[0];
  EXPECT_NE(upload.warnings[0].find("painted"), std::string::npos) << upload.warnings[0];
  EXPECT_EQ(upload.triangles, 2u);
  Image image = render_once(renderer, test::camera_at({0, 0, 3}, {0, 0, 0}, 32, 32), upload.items);
  const uint8_t* p = image.pixel(16, 16);
  EXPECT_EQ(p[0], 0);
  EXPECT_EQ(p[1], 0);
  EXPECT_NEAR(p[2], 255, 1);
}

TEST(SceneUpload, TextureFileIsLoadedOnceAndDrawn) {
  Image texture(1, 1);
  texture.rgba = {255, 0, 255, 255};
  auto file = test::temp_dir() / "magenta.png";
  save_png(texture, file);
  Scene scene = make_scene(textured_quad());
  scene.materials[0].base_color = {1, 1, 1, 1};
  scene.materials[0].base_color_texture = file.string();
  scene.materials.push_back(scene.materials[0]);
  scene.meshes.push_back(scene.meshes[0]);
  scene.meshes[1].material = 1;
  Renderer renderer(test::headless_context());
  SceneUpload upload = upload_scene(renderer, scene);
  EXPECT_TRUE(upload.warnings.empty());
  EXPECT_EQ(upload.textures.size(), 1u);
  Image image = render_once(renderer, test::camera_at({0, 0, 3}, {0, 0, 0}, 32, 32), upload.items);
  const uint8_t* p = image.pixel(16, 16);
  EXPECT_NEAR(p[0], 255, 1);
  EXPECT_EQ(p[1], 0);
  EXPECT_NEAR(p[2], 255, 1);
}

TEST(SceneUpload, ObjectWithMissingMeshIsAnError) {
  Scene scene = make_scene(textured_quad());
  scene.objects[0].mesh = 3;
  Renderer renderer(test::headless_context());
  EXPECT_THROW(upload_scene(renderer, scene), Error);
}

TEST(Renderer, MissingNormalsAreComputedSmooth) {
  Mesh with = test::sphere(1.0f, 16, 32);
  Mesh without = with;
  without.normals.clear();
  Renderer renderer(test::headless_context());
  Camera c = test::camera_at({0, 0, 4}, {0, 0, 0}, 64, 64);
  DrawItem a{renderer.upload_mesh(with), glm::mat4(1.0f), {}};
  DrawItem b{renderer.upload_mesh(without), glm::mat4(1.0f), {}};
  Image ia = render_once(renderer, c, std::span(&a, 1));
  Image ib = render_once(renderer, c, std::span(&b, 1));
  int worst = 0;
  for (size_t i = 0; i < ia.rgba.size(); ++i)
    worst = std::max(worst, std::abs(int(ia.rgba[i]) - int(ib.rgba[i])));
  EXPECT_LE(worst, 6);  // area-weighted normals of a fine sphere are close to the analytic ones
  EXPECT_EQ(test::covered_pixels(ia), test::covered_pixels(ib));
}

TEST(Renderer, MultisamplingSmoothsEdgesOnly) {
  Mesh sphere = test::sphere(1.0f, 32, 64);
  Camera c = test::camera_at({0, 0, 4}, {0, 0, 0}, 96, 96);
  Renderer plain(test::headless_context());
  Renderer msaa(test::headless_context(), {4});
  DrawItem a{plain.upload_mesh(sphere), glm::mat4(1.0f), {}};
  DrawItem b{msaa.upload_mesh(sphere), glm::mat4(1.0f), {}};
  Image ia = render_once(plain, c, std::span(&a, 1));
  Image ib = render_once(msaa, c, std::span(&b, 1));
  EXPECT_NE(ia.rgba, ib.rgba);
  EXPECT_EQ(std::vector(ia.pixel(48, 48), ia.pixel(48, 48) + 4),
            std::vector(ib.pixel(48, 48), ib.pixel(48, 48) + 4));
  EXPECT_NEAR(double(test::covered_pixels(ib)), double(test::covered_pixels(ia)),
              0.1 * double(test::covered_pixels(ia)));
  EXPECT_THROW(Renderer(test::headless_context(), {4096}), Error);
}

// A mesh uploaded once with triangle ranges draws each range as the range's triangles uploaded alone, their
// vertices compacted in first-use order (what extracting a cluster from its record gives), to the pixel:
// the reordering for the vertex cache and the depth range (from the drawn ranges' bounds) come out the same.
// The vertices are numbered backwards, so the record's numbering is not the ranges' first-use order. A range
// is reordered when first prepared; drawing it before is an error.
TEST(Renderer, ARangeOfAMeshDrawsAsTheRangeAlone) {
  Mesh record = test::sphere(1.0f, 24, 48);
  const uint32_t V = uint32_t(record.positions.size());
  std::reverse(record.positions.begin(), record.positions.end());
  std::reverse(record.normals.begin(), record.normals.end());
  for (uint32_t& v : record.indices) v = V - 1 - v;
  const uint32_t T = uint32_t(record.triangle_count());
  const std::vector<uint32_t> ranges = {T / 3, T - T / 3 - T / 5, T / 5};
  std::vector<Mesh> alone;  // each range compacted
  for (uint32_t first = 0; uint32_t t : ranges) {
    Mesh m;
    std::vector<uint32_t> compact(V, UINT32_MAX);
    for (size_t k = 3 * size_t(first); k < 3 * size_t(first + t); ++k) {
      const uint32_t v = record.indices[k];
      if (compact[v] == UINT32_MAX) {
        compact[v] = uint32_t(m.positions.size());
        m.positions.push_back(record.positions[v]), m.normals.push_back(record.normals[v]);
      }
      m.indices.push_back(compact[v]);
    }
    alone.push_back(std::move(m));
    first += t;
  }
  Renderer renderer(test::headless_context());
  const MeshHandle whole = renderer.upload_mesh(record, ranges);
  const Camera c = test::camera_at({0.3f, 0.5f, 2.5f}, {0, 0, 0}, 160, 120, 60.0f);
  DrawItem unprepared{whole, glm::mat4(1.0f), {}, 2};  // a range is reordered before it is drawn
  EXPECT_THROW(render_once(renderer, c, std::span(&unprepared, 1)), Error);
  // The last two ranges alone (the depth range then comes from their bounds only), then every range.
  for (uint32_t from : {1u, 0u}) {
    std::vector<DrawItem> ranged, separate;
    for (uint32_t r = from; r < ranges.size(); ++r) {
      renderer.prepare_range(whole, r, record);
      ranged.push_back({whole, glm::mat4(1.0f), {}, r});
      separate.push_back({renderer.upload_mesh(alone[r]), glm::mat4(1.0f), {}});
    }
    const Image a = render_once(renderer, c, ranged), b = render_once(renderer, c, separate);
    EXPECT_GT(test::covered_pixels(a), 1000u);
    EXPECT_EQ(a.rgba, b.rgba) << "from range " << from;
  }
  DrawItem beyond{whole, glm::mat4(1.0f), {}, uint32_t(ranges.size())};
  EXPECT_THROW(render_once(renderer, c, std::span(&beyond, 1)), Error);
  const std::vector<uint32_t> short_ranges = {T / 3};
  EXPECT_THROW(renderer.upload_mesh(record, short_ranges), Error);
}
