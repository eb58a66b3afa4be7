#include <gtest/gtest.h>

#include "net/http_range.hpp"

using namespace lodstream;
using Kind = RangeRequest::Kind;

TEST(HttpRange, SingleSuffixAndOpenRanges) {
  auto r = parse_range("bytes=0-499", 1000);
  ASSERT_EQ(r.kind, Kind::kSatisfiable);
  ASSERT_EQ(r.ranges.size(), 1u);
  EXPECT_EQ(r.ranges[0].first, 0u);
  EXPECT_EQ(r.ranges[0].last, 499u);
  EXPECT_EQ(content_range(r.ranges[0], 1000), "bytes 0-499/1000");

  r = parse_range("bytes=-300", 1000);
  ASSERT_EQ(r.kind, Kind::kSatisfiable);
  EXPECT_EQ(r.ranges[0].first, 700u);
  EXPECT_EQ(r.ranges[0].last, 999u);

  r = parse_range("bytes=900-", 1000);
  EXPECT_EQ(r.ranges[0].first, 900u);
  EXPECT_EQ(r.ranges[0].last, 999u);

  // Clipped at the end; a suffix longer than the file is the whole file.
  EXPECT_EQ(parse_range("bytes=990-2000", 1000).ranges[0].last, 999u);
  EXPECT_EQ(parse_range("bytes=-5000", 1000).ranges[0].first, 0u);
}

TEST(HttpRange, MultipleRangesAreSortedAndMerged) {
  auto r = parse_range("bytes=500-599, 0-99,100-199 ,900-", 1000);
  ASSERT_EQ(r.kind, Kind::kSatisfiable);
  ASSERT_EQ(r.ranges.size(), 3u);
  EXPECT_EQ(r.ranges[0].first, 0u);
  EXPECT_EQ(r.ranges[0].last, 199u);  // 0-99 and 100-199 are adjacent: one part
  EXPECT_EQ(r.ranges[1].first, 500u);
  EXPECT_EQ(r.ranges[2].last, 999u);
}

TEST(HttpRange, UnsatisfiableWhenEveryRangeStartsPastTheEnd) {
  EXPECT_EQ(parse_range("bytes=1000-1200", 1000).kind, Kind::kUnsatisfiable);
  EXPECT_EQ(parse_range("bytes=5000-,2000-3000", 1000).kind, Kind::kUnsatisfiable);
  EXPECT_EQ(parse_range("bytes=-0", 1000).kind, Kind::kUnsatisfiable);
  EXPECT_EQ(parse_range("bytes=0-10", 0).kind, Kind::kUnsatisfiable);
  // One satisfiable range is enough.
  EXPECT_EQ(parse_range("bytes=5000-,10-20", 1000).kind, Kind::kSatisfiable);
}

TEST(HttpRange, MalformedHeadersAreIgnored) {
  for (const char* h : {"", "items=0-1", "bytes=", "bytes=abc", "bytes=5-1", "bytes=1-2-3", "bytes=-",
                        "bytes=0x10-20", "bytes=99999999999999999999-", "bytes=1,2"})
    EXPECT_EQ(parse_range(h, 1000).kind, Kind::kNone) << h;
  std::string many = "bytes=";
  for (int i = 0; i < 100; ++i) many += std::to_string(i * 2) + "-" + std::to_string(i * 2) + ",";
  EXPECT_EQ(parse_range(many, 1000).kind, Kind::kNone);
  EXPECT_EQ(parse_range(many, 1000, 200).kind, Kind::kSatisfiable);
}
