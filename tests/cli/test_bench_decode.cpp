// `lodstream bench decode`: every codec node of a package decoded, accounted per level as inspect counts
// them.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "baked.hpp"
#include "support/run.hpp"

namespace lodstream::test {
namespace {

TEST(BenchDecode, DecodesEveryNodeOfEveryLevel) {
  const auto package = elephant_package().string();
  auto inspect = run_lodstream({"inspect", package, "--json"});
  ASSERT_EQ(inspect.status, 0) << inspect.err;
  auto bench = run_lodstream({"bench", "decode", package, "--runs", "2", "--json"});
  ASSERT_EQ(bench.status, 0) << bench.err;
  const auto want = inspect.json(), got = bench.json();
  EXPECT_EQ(got["nodes"], want["nodes"]);
  EXPECT_EQ(got["triangles"], want["stored_triangles"]);
  ASSERT_EQ(got["per_level"].size(), want["per_level"].size());
  for (size_t l = 0; l < got["per_level"].size(); ++l) {
    const auto &g = got["per_level"][l], &w = want["per_level"][l];
    EXPECT_EQ(g["level"], w["level"]);
    EXPECT_EQ(g["nodes"], w["nodes"]);
    EXPECT_EQ(g["triangles"], w["triangles"]);
    EXPECT_GT(g["mtris_per_s"].get<double>(), 0.0);
    EXPECT_GE(g["mtris_per_s_nodes_only"].get<double>(), g["mtris_per_s"].get<double>());
  }
  // Pages shared by bytes and records by triangles: the levels' times add up to the run's (one run's medians
  // are its own figures with --runs 1).
  auto once = run_lodstream({"bench", "decode", package, "--runs", "1", "--json"});
  ASSERT_EQ(once.status, 0) << once.err;
  const auto run = once.json();
  double levels_s = 0.0;
  for (const auto& l : run["per_level"]) levels_s += l["pages_s"].get<double>() + l["nodes_s"].get<double>();
  EXPECT_NEAR(levels_s, run["cpu_s"].get<double>(), 1e-6 + 1e-6 * levels_s);
}

TEST(BenchDecode, BadArgumentsAreOneLineErrors) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"bench", "decode", (temp_dir() / "missing.lods").string()},
        std::vector<std::string>{"bench", "decode", data_file("refined_elephant.off").string()},
        std::vector<std::string>{"bench", "decode", elephant_package().string(), "--runs", "0"}}) {
    auto r = run_lodstream(args);
    EXPECT_EQ(r.status, 1) << args.back() << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

}  // namespace
}  // namespace lodstream::test
