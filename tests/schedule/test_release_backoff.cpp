#include <gtest/gtest.h>

#include "schedule/release_backoff.hpp"

using namespace lodstream::schedule;

// Each release of a page doubles the wait before it is due again (up to the cap); other pages are unaffected.
TEST(ReleaseBackoff, EachReleaseOfAPageDoublesItsHoldOff) {
  ReleaseBackoff b(0.25, 1.0);
  EXPECT_FALSE(b.pending());
  b.released(7, 0.0);
  b.released(3, 0.0);
  EXPECT_TRUE(b.pending());
  EXPECT_TRUE(b.due(0.2).empty());
  EXPECT_EQ(b.due(0.25), (std::vector<uint32_t>{3, 7}));
  EXPECT_TRUE(b.due(10.0).empty());  // each release is due once
  b.released(7, 1.0);                // second release: 0.5 s
  EXPECT_TRUE(b.due(1.4).empty());
  EXPECT_EQ(b.due(1.5), std::vector<uint32_t>{7});
  b.released(7, 2.0);  // third: 1.0 s
  b.released(7, 2.0);  // fourth: capped at 1.0 s
  EXPECT_TRUE(b.due(2.9).empty());
  EXPECT_EQ(b.due(3.0), std::vector<uint32_t>{7});
  EXPECT_FALSE(b.pending());
}
