#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "net/wire.hpp"

using namespace lodstream;
using namespace lodstream::wire;

namespace {
Hello hello() {
  Hello h;
  h.package = "city";
  h.cached_hash.low = 7;
  h.held = {{0, 10}, {12, 1}, {100, 50}};
  h.on_disk = {{10, 2}, {13, 4}};
  h.cache_budget_bytes = 256u << 20;
  h.triangles_per_frame = 2'000'000;
  h.viewport_width = 1280, h.viewport_height = 720;
  return h;
}
ViewUpdate view() {
  ViewUpdate v;
  v.client_time_s = 12.5;
  v.eye = {1, 2, 3};
  v.forward = glm::normalize(glm::vec3(1, 0, -1));
  v.velocity = {0.5f, 0, 0};
  v.angular_velocity = {0, 0.1f, 0};
  v.viewport_width = 640, v.viewport_height = 480;
  return v;
}
}  // namespace

TEST(Wire, EveryMessageRoundTrips) {
  std::vector<Message> messages{hello(),
                                view(),
                                Ack{42, 123456, 3.25, 3.0},
                                Welcome{{1, 2}, 99999, 17},
                                Page{5, 9, 1.5, {1, 2, 3, 4, 5}},
                                Bye{"cache full"},
                                Released{{{3, 2}, {9, 1}}},
                                Released{{{4, 1}}, true},
                                Restore{6, 11, 2.75}};
  for (const auto& m : messages) {
    auto frame = encode(m);
    Message back = decode(frame);
    ASSERT_EQ(back.index(), m.index()) << type_name(m);
    EXPECT_EQ(encode(back), frame) << type_name(m);  // every field survived
  }
  auto h = std::get<Hello>(decode(encode(hello())));
  EXPECT_EQ(h.package, "city");
  EXPECT_EQ(h.held.size(), 3u);
  EXPECT_EQ(h.held[2].count, 50u);
  ASSERT_EQ(h.on_disk.size(), 2u);
  EXPECT_EQ(h.on_disk[1].first, 13u);
  EXPECT_TRUE(std::get<Released>(decode(encode(Released{{{4, 1}}, true}))).on_disk);
  EXPECT_FALSE(std::get<Released>(decode(encode(Released{{{4, 1}}, false}))).on_disk);
  EXPECT_EQ(std::get<Restore>(decode(encode(Restore{6, 11, 2.75}))).page_id, 11u);
  EXPECT_EQ(std::get<Page>(decode(encode(Page{5, 9, 1.5, {1, 2, 3}}))).bytes,
            (std::vector<uint8_t>{1, 2, 3}));
}

TEST(Wire, EveryTruncationIsAnError) {
  for (const auto& m : std::vector<Message>{hello(), view(), Page{1, 2, 3.0, std::vector<uint8_t>(100, 9)},
                                            Released{{{1, 2}}, true}, Restore{1, 2, 3.0}}) {
    auto frame = encode(m);
    for (size_t n = 0; n < frame.size(); ++n) {
      // Fix up the length field so the payload parser, not only the length check, sees the cut.
      std::vector<uint8_t> cut(frame.begin(), frame.begin() + long(n));
      if (n >= kHeaderBytes) {
        uint32_t len = uint32_t(n - kHeaderBytes);
        std::memcpy(cut.data() + 4, &len, 4);
      }
      EXPECT_THROW(decode(cut), WireError) << type_name(m) << " cut at " << n;
    }
  }
}

TEST(Wire, InvalidFieldsAreNamed) {
  auto expect_error = [](std::vector<uint8_t> frame, const std::string& needle) {
    try {
      decode(frame);
      ADD_FAILURE() << "accepted; expected an error about " << needle;
    } catch (const WireError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  auto frame = encode(hello());
  frame[0] = 9;
  expect_error(frame, "version");
  frame = encode(hello());
  frame[2] = 77;
  expect_error(frame, "type");
  frame = encode(hello());
  frame.push_back(0);
  expect_error(frame, "length");
  Hello h = hello();
  h.held = {{10, 5}, {12, 1}};  // overlapping
  expect_error(encode(h), "held runs");
  h = hello();
  h.package = std::string(300, 'x');
  expect_error(encode(h), "package");
  ViewUpdate v = view();
  v.forward = {0, 0, 0};
  expect_error(encode(v), "forward");
  v = view();
  v.eye.x = std::numeric_limits<float>::quiet_NaN();
  expect_error(encode(v), "eye");
  v = view();
  v.viewport_width = 0;
  expect_error(encode(v), "viewport");
  // A count claiming more runs than bytes present.
  frame = encode(hello());
  uint32_t huge = 0x40000000;
  std::memcpy(frame.data() + kHeaderBytes + 4 + 4 + 16, &huge, 4);
  expect_error(frame, "held runs count");
  expect_error(encode(Released{}), "released runs");                  // nothing released
  expect_error(encode(Released{{{4, 2}, {5, 1}}}), "released runs");  // overlapping
  frame = encode(Released{{{4, 2}}, true});
  frame.back() = 2;
  expect_error(frame, "on-disk flag");
  h = hello();
  h.on_disk = {{3, 0}};
  expect_error(encode(h), "on-disk runs");  // an empty run
}

TEST(Wire, RandomBytesNeverCrash) {
  std::mt19937 random(1);
  auto base = encode(hello());
  for (int i = 0; i < 20000; ++i) {
    auto frame = base;
    int flips = 1 + int(random() % 4);
    for (int f = 0; f < flips; ++f) frame[random() % frame.size()] = uint8_t(random());
    try {
      Message m = decode(frame);
      EXPECT_EQ(encode(m), frame);  // whatever decodes, re-encodes to the same bytes
    } catch (const WireError&) {
    }
  }
}

TEST(Wire, HeldPagesBecomeRunsTheHelloAccepts) {
  const std::vector<uint32_t> pages{0, 1, 2, 5, 7, 8, 100};
  const auto runs = page_runs(pages);
  ASSERT_EQ(runs.size(), 4u);
  EXPECT_EQ(runs[0].first, 0u);
  EXPECT_EQ(runs[0].count, 3u);
  EXPECT_EQ(runs[1].first, 5u);
  EXPECT_EQ(runs[1].count, 1u);
  EXPECT_EQ(runs[2].first, 7u);
  EXPECT_EQ(runs[2].count, 2u);
  EXPECT_EQ(runs[3].first, 100u);
  EXPECT_TRUE(page_runs({}).empty());
  Hello h = hello();
  h.held = runs;
  EXPECT_EQ(std::get<Hello>(decode(encode(h))).held.back().first, 100u);  // sorted, non-overlapping: valid
}
