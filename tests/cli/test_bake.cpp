// `lodstream bake` and `lodstream inspect` end to end: JSON keys, the package verifies (monotonic errors,
// spheres, decoding, crack-free cuts), multi-object scenes, bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/run.hpp"

using lodstream::test::data_file;
using lodstream::test::run_lodstream;
using lodstream::test::temp_dir;

namespace {

nlohmann::json bake_and_verify(const std::string& model, const std::filesystem::path& out,
                               std::vector<std::string> options = {}) {
  std::vector<std::string> args = {"bake", data_file(model).string(), "-o", out.string(), "--json"};
  args.insert(args.end(), options.begin(), options.end());
  auto bake = run_lodstream(args);
  EXPECT_EQ(bake.status, 0) << bake.err;
  if (bake.status != 0) return {};
  auto j = bake.json();
  for (const char* key :
       {"input_triangles", "objects", "nodes", "pages", "levels", "bytes", "time_s", "peak_rss_bytes"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["bytes"].get<uint64_t>(), std::filesystem::file_size(out));
  EXPECT_NE(bake.err.find("bake: hierarchy"), std::string::npos) << "no progress line";
  // stderr carries only bake's own progress and summary lines, each starting "bake: " (a stray debug print
  // once went to stderr on every bake unnoticed): split at '\r' and '\n'.
  for (size_t start = 0; start < bake.err.size();) {
    size_t end = bake.err.find_first_of("\r\n", start);
    if (end == std::string::npos) end = bake.err.size();
    if (end > start) {
      EXPECT_EQ(bake.err.compare(start, 6, "bake: "), 0) << bake.err.substr(start, end - start);
    }
    start = end + 1;
  }

  auto inspect = run_lodstream({"inspect", out.string(), "--verify", "--json"});
  EXPECT_EQ(inspect.status, 0) << inspect.err;
  auto k = inspect.json();
  EXPECT_EQ(k["verified"], true) << k.dump();
  EXPECT_EQ(k["nodes"], j["nodes"]);
  EXPECT_EQ(k["pages"], j["pages"]);
  EXPECT_EQ(k["levels"], j["levels"]);
  EXPECT_EQ(k["bytes"], j["bytes"]);
  EXPECT_EQ(k["input_triangles"], j["input_triangles"]);
  return j;
}

}  // namespace

TEST(CliBake, ElephantBuildsAVerifiedHierarchy) {
  auto j = bake_and_verify("elephant.off", temp_dir() / "elephant.lods");
  EXPECT_EQ(j["input_triangles"].get<size_t>(), 5558u);
  EXPECT_EQ(j["objects"].get<size_t>(), 1u);
  EXPECT_GE(j["levels"].get<int>(), 3);
  EXPECT_GT(j["nodes"].get<int>(), 44);  // more than the full-resolution clusters alone
  // The phases split the whole bake: their wall times add up to time_s.
  double wall = 0.0;
  for (const char* phase : {"import", "hierarchy", "hlod", "encode_write"}) {
    ASSERT_TRUE(j["phases"].contains(phase)) << phase;
    EXPECT_GE(j["phases"][phase]["wall_s"].get<double>(), 0.0) << phase;
    EXPECT_GE(j["phases"][phase]["cpu_s"].get<double>(), 0.0) << phase;
    wall += j["phases"][phase]["wall_s"].get<double>();
  }
  EXPECT_NEAR(wall, j["time_s"].get<double>(), 0.01);
  for (const char* fallback :
       {"partial", "positions_only", "dropped_components", "abandoned", "stalled_meshes"})
    EXPECT_TRUE(j["fallbacks"].contains(fallback)) << fallback;
}

TEST(CliBake, EveryNodeCodecVerifiesAndEachIsSmallerThanTheLast) {
  // The same hierarchy through codec 1 (meshoptimizer's codecs), codec 2 (predicted positions and normals)
  // and codec 3 (2 with edge-front connectivity): every package passes inspect --verify (crack-free cuts need
  // the predictive codecs' locked vertices exact too), each smaller than the one before.
  const auto dir = temp_dir();
  auto one = bake_and_verify("bunny.obj", dir / "bunny1.lods", {"--codec", "1"});
  auto two = bake_and_verify("bunny.obj", dir / "bunny2.lods", {"--codec", "2"});
  auto three = bake_and_verify("bunny.obj", dir / "bunny3.lods", {"--codec", "3"});
  EXPECT_EQ(one["nodes"], two["nodes"]);
  EXPECT_EQ(one["nodes"], three["nodes"]);
  EXPECT_LT(two["bytes"].get<double>(), 0.9 * one["bytes"].get<double>());
  EXPECT_LT(three["bytes"].get<double>(), 0.95 * two["bytes"].get<double>());
  auto bad = run_lodstream(
      {"bake", data_file("elephant.off").string(), "-o", (dir / "x.lods").string(), "--codec", "4"});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("lodstream: error: --codec"), std::string::npos) << bad.err;
}

TEST(CliBake, MotorBikeKeepsEveryObject) {
  auto info = run_lodstream({"info", data_file("motorBike.obj").string(), "--json"});
  ASSERT_EQ(info.status, 0) << info.err;
  auto j = bake_and_verify("motorBike.obj", temp_dir() / "motorBike.lods");
  EXPECT_EQ(j["objects"], info.json()["objects"]);
  EXPECT_EQ(j["input_triangles"], info.json()["triangles"]);
}

TEST(CliBake, BadInputIsAOneLineError) {
  const auto dir = temp_dir();
  auto missing = run_lodstream({"bake", (dir / "nope.obj").string(), "-o", (dir / "x.lods").string()});
  EXPECT_EQ(missing.status, 1);
  EXPECT_EQ(missing.err.rfind("lodstream: error:", 0), 0u) << missing.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.lods"));

  auto garbage = dir / "garbage.lods";
  std::ofstream(garbage) << "not a package at all";
  auto inspect = run_lodstream({"inspect", garbage.string(), "--verify"});
  EXPECT_EQ(inspect.status, 1);
  EXPECT_NE(inspect.err.find("lodstream: error:"), std::string::npos) << inspect.err;

  // A package with one flipped byte in its data fails --verify with an error naming the file.
  auto good = dir / "elephant.lods";
  ASSERT_EQ(run_lodstream({"bake", data_file("elephant.off").string(), "-o", good.string()}).status, 0);
  {
    std::fstream f(good, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(100);
    char c = 0;
    f.read(&c, 1);
    f.seekp(100);
    c = char(c ^ 0x40);
    f.write(&c, 1);
  }
  auto flipped = run_lodstream({"inspect", good.string(), "--verify"});
  EXPECT_EQ(flipped.status, 1);
  EXPECT_NE(flipped.err.find(good.string()), std::string::npos) << flipped.err;
}

// The DAG's shape options: a smaller --group-ratio stores fewer triangles (about T / (1 - r): 2 T at 0.5,
// 1.5 T at 0.33), --cluster-triangles 256 makes half as many full-resolution clusters (nodes of level 0), and
// --group-clusters reaches the build, and every shape verifies (crack-free cuts, monotonic errors).
TEST(CliBake, DagShapeOptionsSetStoredTrianglesAndClusterSize) {
  const auto dir = temp_dir();
  const auto level0_nodes = [](const std::filesystem::path& package) {
    auto inspect = run_lodstream({"inspect", package.string(), "--json"});
    EXPECT_EQ(inspect.status, 0) << inspect.err;
    return inspect.json()["per_level"][0]["nodes"].get<size_t>();
  };
  const std::vector<std::string> shape = {"--group-ratio", "0.5", "--cluster-triangles", "128"};
  auto half = bake_and_verify("bunny.obj", dir / "half.lods", shape);
  auto third = bake_and_verify("bunny.obj", dir / "third.lods", {"--group-ratio", "0.33"});
  auto large = bake_and_verify("bunny.obj", dir / "large.lods",
                               {"--group-ratio", "0.5", "--cluster-triangles", "256"});
  auto many =
      bake_and_verify("bunny.obj", dir / "many.lods",
                      {"--group-ratio", "0.5", "--cluster-triangles", "128", "--group-clusters", "16"});
  const double input = half["input_triangles"].get<double>();
  EXPECT_GT(half["stored_triangles"].get<double>(), 1.8 * input);
  EXPECT_LT(third["stored_triangles"].get<double>(), 1.6 * input);
  EXPECT_LT(third["levels"].get<int>(), half["levels"].get<int>());
  const size_t clusters_128 = level0_nodes(dir / "half.lods"),
               clusters_256 = level0_nodes(dir / "large.lods");
  EXPECT_GE(clusters_128 * 128, size_t(input));
  EXPECT_GE(clusters_256 * 256, size_t(input));
  EXPECT_LT(double(clusters_256), 0.6 * double(clusters_128));
  // Groups of 16 clusters make another DAG (fewer, larger groups), which verifies too.
  EXPECT_NE(many["bytes"], half["bytes"]);
}

TEST(CliBake, DagShapeOutsideItsRangeIsAOneLineError) {
  const auto dir = temp_dir();
  for (const auto& [option, value] :
       std::vector<std::pair<std::string, std::string>>{{"--group-ratio", "0.8"},
                                                        {"--group-ratio", "0.05"},
                                                        {"--group-clusters", "1"},
                                                        {"--group-clusters", "32"},
                                                        {"--cluster-triangles", "516"},
                                                        {"--cluster-triangles", "130"},
                                                        {"--cluster-triangles", "12"}}) {
    auto bad = run_lodstream(
        {"bake", data_file("elephant.off").string(), "-o", (dir / "x.lods").string(), option, value});
    EXPECT_EQ(bad.status, 1) << option << " " << value;
    EXPECT_EQ(bad.err.rfind("lodstream: error: " + option + ": must be", 0), 0u) << bad.err;
    EXPECT_EQ(bad.err.find('\n'), bad.err.size() - 1) << bad.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.lods"));
  }
}

// A scene of many meshes bakes its meshes in parallel: the package must not depend on thread timing (it did
// while METIS calls ran concurrently and new position ids were numbered in completion order).
TEST(CliBake, TheSameSceneBakesToTheSameBytes) {
  const auto dir = temp_dir();
  std::string bytes[2];
  for (int i = 0; i < 2; ++i) {
    const auto out = dir / ("bike" + std::to_string(i) + ".lods");
    auto bake = run_lodstream({"bake", data_file("motorBike.obj").string(), "-o", out.string()});
    ASSERT_EQ(bake.status, 0) << bake.err;
    std::ifstream in(out, std::ios::binary);
    bytes[i].assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_FALSE(bytes[0].empty());
  EXPECT_TRUE(bytes[0] == bytes[1]) << "two bakes of motorBike differ";
}
