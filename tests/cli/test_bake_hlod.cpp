// HLOD end to end: a layout of many objects (`lodstream gen layout`) bakes by default with an HLOD that
// `inspect
// --verify` accepts (proxy invariants, and the per-object crack test as before); rendered from far away the
// package draws a few proxies where it drew every object's roots without HLOD (--no-hlod), and up close it
// still draws objects; a single object gets no HLOD. Also the buildings.obj verify failure (vertices closer
// than the 2^-14 grid step): its finest grid gets the bits that keep its vertices apart, and it verifies.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/image.hpp"

#include "support/run.hpp"

using lodstream::test::data_file;
using lodstream::test::run_lodstream;
using lodstream::test::temp_dir;

namespace {

std::string csv(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ",") + std::to_string(x);
  return s;
}

// Nodes drawn at 1 px by `render --json` of `package` from `eye` towards `target`.
size_t nodes_drawn(const std::filesystem::path& package, const std::vector<double>& eye,
                   const std::vector<double>& target, const std::filesystem::path& image) {
  auto r =
      run_lodstream({"render", package.string(), "--eye", csv(eye), "--target", csv(target), "--up", "0,0,1",
                     "--size", "320x240", "--pixel-error", "1", "-o", image.string(), "--json"});
  EXPECT_EQ(r.status, 0) << r.err;
  return r.status == 0 ? r.json()["nodes"].get<size_t>() : 0;
}

TEST(CliBakeHlod, ALayoutOfManyObjectsVerifiesAndIsFewNodesFromAfar) {
  const auto dir = temp_dir();
  const auto layout = dir / "layout.obj";
  auto gen = run_lodstream(
      {"gen", "layout", data_file("elephant.off").string(), "--copies", "36", "-o", layout.string()});
  ASSERT_EQ(gen.status, 0) << gen.err;
  const auto with = dir / "with.lods", without = dir / "without.lods";
  auto bake = run_lodstream({"bake", layout.string(), "-o", with.string(), "--json"});  // HLOD by default
  ASSERT_EQ(bake.status, 0) << bake.err;
  const auto j = bake.json();
  EXPECT_EQ(j["objects"].get<size_t>(), 36u);
  EXPECT_GE(j["hlod"]["nodes"].get<size_t>(), 9u + 3u);  // leaves of <= 4 objects, and their parents
  EXPECT_GE(j["hlod"]["levels"].get<uint32_t>(), 2u);
  auto plain = run_lodstream({"bake", layout.string(), "-o", without.string(), "--json", "--no-hlod"});
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(plain.json()["hlod"]["nodes"].get<size_t>(), 0u);
  EXPECT_EQ(plain.json()["nodes"].get<size_t>() + j["hlod"]["nodes"].get<size_t>(), j["nodes"].get<size_t>());

  auto inspect = run_lodstream({"inspect", with.string(), "--verify", "--json"});
  EXPECT_EQ(inspect.status, 0) << inspect.err;
  EXPECT_EQ(inspect.json()["verified"], true) << inspect.out;
  // inspect lists the proxies by HLOD level: as many as the bake made, over as many levels.
  const nlohmann::json hlod_levels = inspect.json()["hlod_levels"];
  size_t proxies = 0;
  for (const auto& level : hlod_levels) proxies += level["nodes"].get<size_t>();
  EXPECT_EQ(proxies, j["hlod"]["nodes"].get<size_t>());
  EXPECT_EQ(hlod_levels.size(), j["hlod"]["levels"].get<size_t>());

  auto info = run_lodstream({"info", layout.string(), "--json"});
  ASSERT_EQ(info.status, 0) << info.err;
  const auto b = info.json()["bounds"];
  std::vector<double> lo = b["min"].get<std::vector<double>>(), hi = b["max"].get<std::vector<double>>();
  std::vector<double> centre(3), far(3), near(3);
  double diagonal = 0.0;
  for (int a = 0; a < 3; ++a) {
    centre[a] = 0.5 * (lo[a] + hi[a]);
    diagonal += (hi[a] - lo[a]) * (hi[a] - lo[a]);
  }
  diagonal = std::sqrt(diagonal);
  far = {centre[0], centre[1] - 30.0 * diagonal, centre[2] + 30.0 * diagonal};
  near = {lo[0] - 0.05 * diagonal, lo[1] - 0.05 * diagonal, hi[2]};
  const size_t far_with = nodes_drawn(with, far, centre, dir / "far_with.png");
  const size_t far_without = nodes_drawn(without, far, centre, dir / "far_without.png");
  EXPECT_LE(far_with, 16u);
  EXPECT_GE(far_without, 36u) << "every object's roots";
  // Up close the nearest objects are refined below their leaf proxy: more nodes than from afar.
  EXPECT_GT(nodes_drawn(with, near, centre, dir / "near_with.png"), far_with);
}

TEST(CliBakeHlod, OneObjectHasNoHlod) {
  auto bake = run_lodstream({"bake", data_file("elephant.off").string(), "-o",
                             (temp_dir() / "e.lods").string(), "--json", "--hlod"});
  ASSERT_EQ(bake.status, 0) << bake.err;
  EXPECT_EQ(bake.json()["hlod"]["nodes"].get<size_t>(), 0u);
}

// buildings.obj tessellates footprints with vertices 0.013 apart, under the 2^-14 step (0.017) of its
// diagonal: on that grid its finest level welded into slivers and --verify failed; the separating grid
// keeps them apart.
TEST(CliBakeHlod, BuildingsVerifiesOnItsSeparatingGrid) {
  const auto out = temp_dir() / "buildings.lods";
  auto bake = run_lodstream({"bake", data_file("buildings.obj").string(), "-o", out.string(), "--json"});
  ASSERT_EQ(bake.status, 0) << bake.err;
  EXPECT_GT(bake.json()["grid_bits_max"].get<int>(), 14);
  auto inspect = run_lodstream({"inspect", out.string(), "--verify", "--json"});
  EXPECT_EQ(inspect.status, 0) << inspect.err;
  EXPECT_EQ(inspect.json()["verified"], true) << inspect.out;
}

// Two flat 8 x 8 grids side by side, objects of their own, the left one red, the right one blue: from afar
// the package draws the one proxy that merges them, and it shows both colours where the objects are.
TEST(CliBakeHlod, AProxyOfTwoMaterialsRendersWithTheirColours) {
  const auto dir = temp_dir();
  std::ofstream(dir / "two.mtl") << "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n";
  {
    std::ofstream obj(dir / "two.obj");
    obj << "mtllib two.mtl\n";
    const int n = 8;
    for (int g = 0; g < 2; ++g) {
      obj << "o grid" << g << "\nusemtl " << (g == 0 ? "red" : "blue") << "\n";
      const int base = g * (n + 1) * (n + 1) + 1;
      for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x)
          obj << "v " << (g == 0 ? -3.0 : 1.0) + 2.0 * x / n << " " << -1.0 + 2.0 * y / n << " 0\n";
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const int a = base + y * (n + 1) + x;
          obj << "f " << a << " " << a + 1 << " " << a + n + 2 << "\nf " << a << " " << a + n + 2 << " "
              << a + n + 1 << "\n";
        }
    }
  }
  const auto package = dir / "two.lods", image = dir / "two.png";
  auto bake = run_lodstream({"bake", (dir / "two.obj").string(), "-o", package.string(), "--json"});
  ASSERT_EQ(bake.status, 0) << bake.err;
  ASSERT_EQ(bake.json()["hlod"]["nodes"].get<size_t>(), 1u);
  auto r = run_lodstream({"render", package.string(), "--eye", "0,0,12", "--target", "0,0,0", "--up", "0,1,0",
                          "--size", "320x240", "--pixel-error", "1000", "-o", image.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.json()["nodes"].get<size_t>(), 1u) << "the proxy alone";
  const lodstream::Image img = lodstream::load_image(image);
  size_t red_left = 0, blue_right = 0, misplaced = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.pixel(x, y);
      const bool red = p[0] > 2 * p[2] + 40, blue = p[2] > 2 * p[0] + 40;
      const bool left = x < img.width / 2;
      red_left += red && left;
      blue_right += blue && !left;
      misplaced += (red && !left) || (blue && left);
    }
  EXPECT_GT(red_left, 500u);
  EXPECT_GT(blue_right, 500u);
  EXPECT_EQ(misplaced, 0u);
}

}  // namespace
