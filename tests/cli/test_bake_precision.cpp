// Bake's precision rule on a real package (refined_elephant): every node header's position shift and normal
// bits follow cmd_bake.cpp's rule. Level 0 keeps --normal-bits (9); coarser page groups store at most
// --coarse-normal-bits (8), and one bit less where the page group's position shift is 2 or more.
#include <gtest/gtest.h>

#include "baked.hpp"
#include "package/reader.hpp"

using namespace lodstream;

TEST(BakePrecision, CoarseNodesOfShiftTwoOrMoreStoreOneNormalBitLess) {
  auto reader = package::PackageReader::open(test::elephant_package());
  size_t shifted = 0, coarse = 0, finest = 0;
  uint32_t loaded_page = UINT32_MAX;
  std::vector<uint8_t> page;
  for (uint32_t id = 0; id < reader.node_count(); ++id) {
    const package::NodeRecord record = reader.node(id);
    if (record.page != loaded_page) page = reader.read_page(record.page), loaded_page = record.page;
    // The common node header (node_header.hpp): u8 format, u8 flags, u8 position shift, u8 normal bits.
    const std::span<const uint8_t> bytes = reader.node_bytes(id, page);
    ASSERT_GE(bytes.size(), 4u);
    const uint32_t shift = bytes[2], normal_bits = bytes[3];
    if (shift >= 2) {
      EXPECT_EQ(normal_bits, 7u) << "node " << id << " shift " << shift;
      ++shifted;
    } else if (record.level == 0) {
      EXPECT_EQ(normal_bits, 9u) << "node " << id;  // a record with a level-0 cluster keeps the finest bits
      ++finest;
    } else {
      EXPECT_TRUE(normal_bits == 8u || normal_bits == 9u) << "node " << id << " bits " << normal_bits;
      coarse += normal_bits == 8u;
    }
  }
  EXPECT_GT(shifted, 0u);
  EXPECT_GT(coarse, 0u);
  EXPECT_GT(finest, 0u);
}
