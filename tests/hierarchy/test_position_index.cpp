// Exact position identity (position_index.hpp): the bulk weld gives every position the id that inserting the
// positions one by one into a PositionIndex gives, on inputs large enough for many buckets and chunks.
#include <gtest/gtest.h>

#include <random>

#include "hierarchy/position_index.hpp"

namespace lodstream::hierarchy {
namespace {

std::vector<uint32_t> inserted_ids(const std::vector<glm::vec3>& positions, uint32_t& distinct) {
  PositionIndex index;
  std::vector<uint32_t> ids;
  for (const glm::vec3& p : positions) ids.push_back(index.insert(p));
  distinct = uint32_t(index.size());
  return ids;
}

// Coordinates drawn from a few values (many repeats, -0 among them) so that most positions recur.
std::vector<glm::vec3> repeating_positions(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  const float values[] = {-0.0f, 0.0f, 1.0f, -1.5f, 2.25f, 1e-30f, 3e7f, 0.1f, -7.0f, 42.0f, 0.5f, 9.75f};
  std::uniform_int_distribution<int> pick(0, int(std::size(values)) - 1);
  std::vector<glm::vec3> positions(n);
  for (glm::vec3& p : positions) p = {values[pick(rng)], values[pick(rng)], values[pick(rng)]};
  return positions;
}

TEST(PositionIndex, BulkWeldMatchesInsertsOnManyBuckets) {
  for (size_t n : {size_t(0), size_t(1), size_t(700), size_t(300000)}) {
    const std::vector<glm::vec3> positions = repeating_positions(n, uint32_t(n));
    uint32_t expected_distinct = 0, distinct = 7;
    const std::vector<uint32_t> expected = inserted_ids(positions, expected_distinct);
    EXPECT_EQ(weld_positions(positions, distinct), expected) << n << " positions";
    EXPECT_EQ(distinct, expected_distinct) << n << " positions";
  }
}

TEST(PositionIndex, BulkWeldOfDistinctPositionsNumbersThemInOrder) {
  std::vector<glm::vec3> positions;
  for (int i = 0; i < 5000; ++i) positions.emplace_back(float(i), float(i % 7), -float(i % 3));
  positions.emplace_back(-0.0f, 0.0f, -0.0f);  // the same position as (0, 0, 0) at index 0
  uint32_t distinct = 0;
  const std::vector<uint32_t> ids = weld_positions(positions, distinct);
  EXPECT_EQ(distinct, 5000u);
  for (uint32_t i = 0; i < 5000; ++i) ASSERT_EQ(ids[i], i);
  EXPECT_EQ(ids[5000], 0u);
}

}  // namespace
}  // namespace lodstream::hierarchy
