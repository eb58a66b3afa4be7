#include <gtest/gtest.h>

#include "schedule/cache_budget.hpp"

using namespace lodstream;

// A cache smaller than the decompressed pages affords its share of the input triangles; one that holds every
// page, or a package that does not say how many triangles it came from, sets no limit.
TEST(CacheBudget, ACacheAffordsItsShareOfTheInputTriangles) {
  package::RootIndex root;
  root.pages.resize(2);
  root.pages[0].raw_size = 1000;
  root.pages[1].raw_size = 3000;
  root.scene.input_triangles = 400;
  EXPECT_EQ(schedule::affordable_triangles(root, 2000), 200u);
  EXPECT_EQ(schedule::affordable_triangles(root, 1), 0u);
  EXPECT_EQ(schedule::affordable_triangles(root, 4000), UINT64_MAX);
  root.scene.input_triangles = 0;
  EXPECT_EQ(schedule::affordable_triangles(root, 2000), UINT64_MAX);
}
