#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "runtime/cache.hpp"
#include "support/synthetic_dag.hpp"

using namespace lodstream;
using namespace lodstream::runtime;

namespace {
const package::ContentHash kA{1, 2}, kB{3, 4};
std::vector<uint8_t> bytes(size_t n, uint8_t v = 7) {
  return std::vector<uint8_t>(n, v);
}
}  // namespace

TEST(PageCache, StaysUnderBudgetLeastRecentlyUsedFirstAmongEquals) {
  PageCache cache(300);
  cache.insert(kA, 0, bytes(100));
  cache.insert(kA, 1, bytes(100));
  cache.insert(kA, 2, bytes(100));
  cache.set_usefulness(kA, {}, {{0, 1.0}, {1, 1.0}, {2, 1.0}});
  ASSERT_NE(cache.find(kA, 0), nullptr);  // 0 is now more recent than 1
  cache.insert(kA, 3, bytes(100));
  EXPECT_EQ(cache.bytes(), 300u);
  EXPECT_EQ(cache.pages(kA), (std::vector<uint32_t>{0, 2, 3}));
  EXPECT_EQ(cache.evicted_pages(), 1u);
  // Unrated arrivals that overflow the budget: the newest goes (they arrive most useful first).
  PageCache burst(300);
  for (uint32_t p = 0; p < 5; ++p) burst.insert(kA, p, bytes(100));
  EXPECT_EQ(burst.pages(kA), (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(*cache.find(kA, 3), bytes(100));
  cache.insert(kA, 3, bytes(50, 9));  // replacing a page updates the byte count
  EXPECT_EQ(cache.bytes(), 250u);
  EXPECT_EQ(cache.find(kA, 3)->front(), 9);
}

TEST(PageCache, EvictsTheLeastUsefulFirstAndNeverAPinnedPage) {
  PageCache cache(400);
  for (uint32_t p = 0; p < 4; ++p) cache.insert(kA, p, bytes(100));
  // Page 0 is the oldest but the most useful; page 3 the newest but useless; page 1 pinned though useless.
  const std::vector<uint32_t> pinned = {1};
  cache.set_usefulness(kA, pinned, {{0, 50.0}, {2, 5.0}});
  cache.insert(kA, 4, bytes(100));
  EXPECT_FALSE(cache.contains(kA, 3));
  cache.insert(kA, 5, bytes(100));  // 4 is unrated (fetched for a cut): the least useful rated page, 2, goes
  EXPECT_EQ(cache.pages(kA), (std::vector<uint32_t>{0, 1, 4, 5}));
  cache.set_usefulness(kA, pinned, {{0, 50.0}, {4, 1.0}, {5, 2.0}});
  cache.insert(kA, 6, bytes(150));  // 4, then 5 go; 0 (useful) and 1 (pinned) stay
  EXPECT_EQ(cache.pages(kA), (std::vector<uint32_t>{0, 1, 6}));
  EXPECT_LE(cache.bytes(), cache.budget());
  // Pinned pages alone may exceed the budget; nothing pinned is ever dropped.
  PageCache small(100);
  small.insert(kA, 0, bytes(80));
  const std::vector<uint32_t> both = {0, 1};
  small.set_usefulness(kA, both, {});
  small.insert(kA, 1, bytes(80));  // unpinned when inserted (pins apply to held pages): evicted
  EXPECT_FALSE(small.contains(kA, 1));
  small.insert(kA, 1, bytes(10));
  small.set_usefulness(kA, both, {});
  EXPECT_TRUE(small.contains(kA, 0));
  EXPECT_TRUE(small.contains(kA, 1));
}

TEST(PageCache, KeyedByContentHashSoAReconnectFindsItsPages) {
  PageCache cache(1000);
  cache.insert(kA, 5, bytes(10));
  cache.insert(kA, 9, bytes(10));
  cache.insert(kB, 5, bytes(10, 1));
  // A new session on the same content finds the pages; another package's pages never mix in.
  EXPECT_EQ(cache.pages(kA), (std::vector<uint32_t>{5, 9}));
  EXPECT_EQ(cache.find(kB, 5)->front(), 1);
  EXPECT_EQ(cache.find(kA, 5)->front(), 7);
  EXPECT_EQ(cache.find(package::ContentHash{1, 3}, 5), nullptr);
  cache.clear(kA);
  EXPECT_TRUE(cache.pages(kA).empty());
  EXPECT_EQ(cache.bytes(), 10u);
}

TEST(PageUsefulness, PinsTheCutAndRanksByTheErrorDroppingAPageWouldShow) {
  test::SyntheticDag dag = test::SyntheticDag::make();
  for (uint32_t i = 0; i < dag.records.size(); ++i) dag.records[i].page = i;  // one node per page
  test::TestNodes nodes(dag);
  auto scene = dag.scene({glm::mat4(1.0f)});
  Camera c;
  c.eye = {-1.0f, 0.5f, 1.0f};
  c.target = {8.0f, 0.0f, 0.0f};
  View now = View::of(c);
  Cut cut = select_cut(scene, nodes, now, {1.0});
  std::vector<uint32_t> all(dag.records.size());
  for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  const View views[] = {now};
  PageUsefulness u = page_usefulness(scene, nodes, cut, views, all);
  std::vector<uint32_t> drawn;
  for (const auto& d : cut.drawn) drawn.push_back(d.node);
  EXPECT_EQ(u.pinned, drawn);                          // page == node id here
  EXPECT_TRUE(std::isinf(u.usefulness.at(28)));        // roots
  EXPECT_GT(u.usefulness.at(0), u.usefulness.at(15));  // the near leaf matters more than the far one
  // A predicted view at the far end raises the far leaf's usefulness.
  Camera later = c;
  later.eye = {17.0f, 0.5f, 1.0f};
  later.target = {8.0f, 0.0f, 0.0f};
  const View both[] = {now, View::of(later)};
  PageUsefulness p = page_usefulness(scene, nodes, cut, both, all);
  EXPECT_GT(p.usefulness.at(15), u.usefulness.at(15));
  EXPECT_DOUBLE_EQ(p.usefulness.at(0), u.usefulness.at(0));

  // Fed to the cache: under pressure the far leaves go first, the cut's pages stay.
  PageCache cache(1u << 20);
  for (uint32_t i : all) cache.insert(kA, i, bytes(100));
  cache.set_usefulness(kA, u.pinned, u.usefulness);
  EXPECT_EQ(cache.pages(kA).size(), all.size());
  cache.set_budget(20 * 100);
  for (uint32_t pinned : u.pinned) EXPECT_TRUE(cache.contains(kA, pinned));
  EXPECT_TRUE(cache.contains(kA, 28) && cache.contains(kA, 29));
  EXPECT_LE(cache.bytes(), cache.budget());
  EXPECT_FALSE(cache.contains(kA, 15));
}
