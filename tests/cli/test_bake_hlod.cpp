// HLOD end to end: a layout of many objects (`lodstream gen layout`) bakes with an HLOD that `inspect
// --verify` accepts (proxy invariants, and the per-object crack test as before); rendered from far away the
// package draws a few proxies where it drew every object's roots without HLOD, and up close it still draws
// objects; a single object gets no HLOD. Also the buildings.obj verify failure (vertices closer than the
// 2^-14 grid step): its finest grid gets the bits that keep its vertices apart, and it verifies.
#include <gtest/gtest.h>

#include <filesystem>

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
  auto bake = run_lodstream({"bake", layout.string(), "-o", with.string(), "--json", "--hlod"});
  ASSERT_EQ(bake.status, 0) << bake.err;
  const auto j = bake.json();
  EXPECT_EQ(j["objects"].get<size_t>(), 36u);
  EXPECT_GE(j["hlod"]["nodes"].get<size_t>(), 9u + 3u);  // leaves of <= 4 objects, and their parents
  EXPECT_GE(j["hlod"]["levels"].get<uint32_t>(), 2u);
  auto plain = run_lodstream({"bake", layout.string(), "-o", without.string(), "--json"});
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(plain.json()["hlod"]["nodes"].get<size_t>(), 0u);
  EXPECT_EQ(plain.json()["nodes"].get<size_t>() + j["hlod"]["nodes"].get<size_t>(), j["nodes"].get<size_t>());

  auto inspect = run_lodstream({"inspect", with.string(), "--verify", "--json"});
  EXPECT_EQ(inspect.status, 0) << inspect.err;
  EXPECT_EQ(inspect.json()["verified"], true) << inspect.out;

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

}  // namespace
