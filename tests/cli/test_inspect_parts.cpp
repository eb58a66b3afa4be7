// `lodstream inspect --parts` (package/size_account.hpp, package/index_account.hpp) and bake's normal
// precision by level
// (--coarse-normal-bits): level 0 keeps --normal-bits, coarser clusters spend fewer normal bytes.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/run.hpp"

namespace lodstream::test {
namespace {

nlohmann::json bake_and_account(const std::filesystem::path& out, std::vector<std::string> options) {
  std::vector<std::string> args = {"bake", data_file("elephant.off").string(), "-o", out.string(), "--json"};
  args.insert(args.end(), options.begin(), options.end());
  auto bake = run_lodstream(args);
  EXPECT_EQ(bake.status, 0) << bake.err;
  auto inspect = run_lodstream({"inspect", out.string(), "--parts", "--json"});
  EXPECT_EQ(inspect.status, 0) << inspect.err;
  return inspect.json();
}

TEST(CliInspectParts, CoarseClustersStoreFewerNormalBitsAndLevelZeroKeepsItsOwn) {
  const auto ten = bake_and_account(temp_dir() / "ten.lods", {"--coarse-normal-bits", "10"});
  const auto six = bake_and_account(temp_dir() / "six.lods", {"--coarse-normal-bits", "6"});
  ASSERT_TRUE(ten.contains("parts"));
  ASSERT_EQ(ten["parts"].size(), six["parts"].size());
  ASSERT_GE(ten["parts"].size(), 3u);
  uint64_t coarse_ten = 0, coarse_six = 0;
  for (size_t l = 0; l < ten["parts"].size(); ++l) {
    const auto &a = ten["parts"][l], &b = six["parts"][l];
    ASSERT_EQ(a["level"], b["level"]);
    EXPECT_EQ(a["triangles"], b["triangles"]);  // the hierarchy does not depend on the normal bits
    EXPECT_GT(a["vertices"].get<uint64_t>(), a["triangles"].get<uint64_t>() / 3);
    for (const char* part :
         {"header", "positions", "normals", "attributes", "locked", "connectivity", "references"})
      ASSERT_TRUE(a["raw"].contains(part) && a["compressed"].contains(part)) << part;
    if (a["level"] == 0) {
      EXPECT_EQ(a["raw"], b["raw"]);  // level 0: the same bytes
    } else {
      coarse_ten += a["compressed"]["normals"].get<uint64_t>();
      coarse_six += b["compressed"]["normals"].get<uint64_t>();
    }
  }
  EXPECT_LT(coarse_six, coarse_ten);
  EXPECT_LT(six["bytes"].get<uint64_t>(), ten["bytes"].get<uint64_t>());
  // The index's account (package/index_account.hpp): every record; the fields that do not say where a node's
  // bytes are do not depend on the normal bits.
  ASSERT_TRUE(ten.contains("index_parts"));
  EXPECT_EQ(ten["index_parts"]["records"], ten["nodes"]);
  for (const char* field : {"triangle counts", "children", "parents", "pair errors", "sphere centres"})
    EXPECT_EQ(ten["index_parts"]["raw"][field], six["index_parts"]["raw"][field]) << field;
  EXPECT_EQ(ten["index_parts"]["raw"]["record heads"], ten["nodes"]);  // one head byte per record
}

TEST(CliInspectParts, BadCoarseNormalBitsIsAOneLineError) {
  auto r = run_lodstream({"bake", data_file("elephant.off").string(), "-o", (temp_dir() / "x.lods").string(),
                          "--coarse-normal-bits", "3"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--coarse-normal-bits"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

}  // namespace
}  // namespace lodstream::test
