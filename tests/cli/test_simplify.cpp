// `lodstream simplify` end to end: targets, JSON keys, the written mesh, bad arguments.
#include <gtest/gtest.h>

#include "support/run.hpp"

using lodstream::test::data_file;
using lodstream::test::run_lodstream;
using lodstream::test::temp_dir;

TEST(CliSimplify, RatioWritesMeshAndReportsJson) {
  auto out = temp_dir() / "bunny_10.ply";
  auto r = run_lodstream(
      {"simplify", data_file("bunny.obj").string(), "-o", out.string(), "--ratio", "0.1", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  // Under a million triangles there is no progress bar, and --json output is for machines: nothing else is
  // written (a stray debug print once went to stderr on every run unnoticed).
  EXPECT_EQ(r.err, "");
  auto j = r.json();
  size_t in = j["input_triangles"], got = j["output_triangles"];
  EXPECT_GT(in, 60000u);
  EXPECT_NEAR(double(got), 0.1 * double(in), 0.01 * 0.1 * double(in) + 1);
  EXPECT_GT(j["error_bound"].get<double>(), 0.0);
  EXPECT_GT(j["time_s"].get<double>(), 0.0);
  auto info = run_lodstream({"info", out.string(), "--json"});
  ASSERT_EQ(info.status, 0) << info.err;  // the written file reads back
  EXPECT_EQ(info.json()["triangles"].get<size_t>(), got);
}

TEST(CliSimplify, ErrorRelativeIsNotExceeded) {
  auto out = temp_dir() / "horse.obj";
  auto r = run_lodstream({"simplify", data_file("horse.ply").string(), "-o", out.string(), "--error-relative",
                          "0.01", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = r.json();
  EXPECT_LT(j["output_triangles"].get<size_t>(), j["input_triangles"].get<size_t>());
  EXPECT_GT(j["error_bound"].get<double>(), 0.0);
}

TEST(CliSimplify, BadArgumentsAreOneLineErrors) {
  auto out = (temp_dir() / "x.ply").string();
  auto model = data_file("bunny.obj").string();
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"simplify", model, "-o", out},
           {"simplify", model, "-o", out, "--ratio", "0.5", "--triangles", "10"},
           {"simplify", model, "-o", out, "--ratio", "1.5"},
           {"simplify", model, "-o", (temp_dir() / "x.stl").string(), "--ratio", "0.5"},
           {"simplify", "/nonexistent.obj", "-o", out, "--ratio", "0.5"}}) {
    auto r = run_lodstream(args);
    EXPECT_EQ(r.status, 1) << args[4];
    EXPECT_NE(r.err.find("lodstream: error:"), std::string::npos) << r.err;
  }
}

TEST(CliSimplify, AllowTopologyChangeReachesWhatCollapseCannot) {
  // motorBike has hundreds of parts: topology-preserving collapse keeps a few triangles of each.
  auto out = temp_dir() / "bike.ply";
  std::vector<std::string> args = {
      "simplify", data_file("motorBike.obj").string(), "-o", out.string(), "--triangles", "200", "--json"};
  auto stuck = run_lodstream(args);
  ASSERT_EQ(stuck.status, 0) << stuck.err;
  EXPECT_FALSE(stuck.json()["target_reached"].get<bool>());
  EXPECT_NE(stuck.err.find("short of the target"), std::string::npos);
  args.push_back("--allow-topology-change");
  auto r = run_lodstream(args);
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = r.json();
  EXPECT_TRUE(j["target_reached"].get<bool>());
  EXPECT_LE(j["output_triangles"].get<size_t>(), 200u);
  EXPECT_GT(j["output_triangles"].get<size_t>(), 0u);
  EXPECT_GE(j["error_bound"].get<double>(), stuck.json()["error_bound"].get<double>());
}

TEST(CliSimplify, BenchComparesWithMeshoptimizerAtItsTriangleCount) {
  auto r = run_lodstream(
      {"bench", "simplify", data_file("elephant.off").string(), "--ratio", "0.5", "--runs", "2", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = r.json();
  EXPECT_EQ(j["runs"].get<int>(), 2);
  const size_t meshopt = j["meshoptimizer"]["triangles"];
  EXPECT_GT(meshopt, 0u);
  EXPECT_LE(meshopt, j["input_triangles"].get<size_t>() / 2 + 1);
  for (const char* side : {"meshoptimizer", "lodstream", "lodstream_positions_only"}) {
    const auto& s = j[side];
    EXPECT_EQ(s["triangles"].get<size_t>(), meshopt) << side;  // both sides at meshoptimizer's count
    EXPECT_GT(s["time_s"].get<double>(), 0.0) << side;
    EXPECT_GT(s["cpu_s"].get<double>(), 0.0) << side;
    EXPECT_GE(s["hausdorff_relative"].get<double>(), s["mean_relative"].get<double>()) << side;
    EXPECT_GT(s["mean_relative"].get<double>(), 0.0) << side;
    EXPECT_GT(s["psnr"].get<double>(), 20.0) << side;
  }
}
