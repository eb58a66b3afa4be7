// Bake's precision rule on a real package (refined_elephant): every node header's normal bits follow
// cmd_bake.cpp's rule. Level 0 keeps --normal-bits (9); coarser page groups store at most
// --coarse-normal-bits (7), and one bit less (6) where the page group's finest cluster has an error of 16
// finest grid steps or more (format 14; format 13 stored 8, and 7 from 64 steps).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <utility>

#include "baked.hpp"
#include "package/reader.hpp"

using namespace lodstream;

TEST(BakePrecision, CoarseNodesStoreSevenNormalBitsAndSixFromSixteenSteps) {
  auto reader = package::PackageReader::open(test::elephant_package());
  struct Record {
    uint32_t first = 0, level = UINT32_MAX;
    float steps = INFINITY;  // the smallest error of its clusters, in finest grid steps
  };
  std::map<std::pair<uint32_t, uint32_t>, Record> records;  // by (page, offset)
  for (uint32_t id = 0; id < reader.node_count(); ++id) {
    const package::NodeRecord n = reader.node(id);
    Record& r = records.try_emplace({n.page, n.offset}, Record{id}).first->second;
    r.level = std::min(r.level, n.level);
    r.steps = std::min(r.steps, n.error / reader.scene().representations[n.representation].grid.step);
  }
  size_t six = 0, seven = 0, finest = 0;
  uint32_t loaded_page = UINT32_MAX;
  std::vector<uint8_t> page;
  for (const auto& [where, r] : records) {
    if (where.first != loaded_page) page = reader.read_page(where.first), loaded_page = where.first;
    // The common node header (node_header.hpp): u8 format, u8 flags, u8 position shift, u8 normal bits.
    const std::span<const uint8_t> bytes = reader.node_bytes(r.first, page);
    ASSERT_GE(bytes.size(), 4u);
    const uint32_t normal_bits = bytes[3];
    if (r.level == 0) {
      EXPECT_EQ(normal_bits, 9u) << "node "
                                 << r.first;  // a record with a level-0 cluster keeps the finest bits
      ++finest;
    } else if (r.steps >= 20.0f) {  // stored errors are rounded up a little (pair_rounding.hpp): a margin
      EXPECT_EQ(normal_bits, 6u) << "node " << r.first << ", " << r.steps << " steps";
      ++six;
    } else if (r.steps < 14.0f) {
      EXPECT_EQ(normal_bits, 7u) << "node " << r.first << ", " << r.steps << " steps";
      ++seven;
    } else {
      EXPECT_TRUE(normal_bits == 6u || normal_bits == 7u) << "node " << r.first << " bits " << normal_bits;
    }
  }
  EXPECT_GT(six, 0u);
  EXPECT_GT(seven, 0u);
  EXPECT_GT(finest, 0u);
}
