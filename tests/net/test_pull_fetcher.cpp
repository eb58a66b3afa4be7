// PullFetcher's reconnection (issue 5: a pulling client whose server goes away keeps its requests and fetches
// them again once the server is back): a failed read is retried on a new source with back-off, and reported
// only after retry_s of failures.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "core/error.hpp"
#include "net/pull_fetcher.hpp"

using namespace lodstream;

namespace {

// A source of `size` bytes (byte i = i % 251) whose reads fail while `outage` counts down (each failed read
// takes one off; negative: fails forever), as reads from a server that went away do.
struct Flaky {
  std::atomic<int> outage{0};
  std::atomic<int> sources{0};  // sources made
  bool first_fails = false;     // the very first source cannot be made

  struct Source final : package::ByteSource {
    Flaky* flaky;
    std::string label = "flaky";
    explicit Source(Flaky* f) : flaky(f) {}
    uint64_t size() const override { return 1 << 20; }
    const std::string& name() const override { return label; }
    void read(uint64_t offset, std::span<uint8_t> out) const override {
      if (flaky->outage != 0) {
        if (flaky->outage > 0) --flaky->outage;
        throw Error("flaky: connection refused");
      }
      for (size_t i = 0; i < out.size(); ++i) out[i] = uint8_t((offset + i) % 251);
    }
  };
  PullFetcher::SourceFactory factory() {
    return [this] {
      if (first_fails) throw Error("flaky: cannot connect");
      ++sources;
      return std::make_shared<Source>(this);
    };
  }
};

PullOptions fast_retries(double retry_s) {
  PullOptions o;
  o.connections = 1;
  o.first_backoff_s = 0.001;
  o.max_backoff_s = 0.004;
  o.retry_s = retry_s;
  return o;
}

// Waits (up to 10 s, polling) until the inbox holds a page or an error.
std::vector<ArrivedPage> wait_for(PageInbox& inbox) {
  std::vector<ArrivedPage> got;
  for (int i = 0; i < 5000 && got.empty() && inbox.error().empty(); ++i) {
    got = inbox.take();
    if (got.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return got;
}

const package::Range kRange{1000, 64, 64, 0};

}  // namespace

TEST(PullFetcher, AReadThatFailsIsRetriedOnANewSourceUntilTheServerIsBack) {
  Flaky flaky;
  flaky.outage = 3;
  PageInbox inbox;
  PullFetcher fetcher(flaky.factory(), inbox, fast_retries(30.0));
  fetcher.request({schedule::PageKind::data, 7, 64}, kRange);
  const auto got = wait_for(inbox);
  ASSERT_EQ(got.size(), 1u) << inbox.error();
  EXPECT_TRUE(inbox.error().empty()) << inbox.error();
  EXPECT_EQ(got[0].page.id, 7u);
  ASSERT_EQ(got[0].bytes.size(), 64u);
  for (size_t i = 0; i < 64; ++i) EXPECT_EQ(got[0].bytes[i], uint8_t((1000 + i) % 251)) << i;
  EXPECT_EQ(fetcher.reconnects(), 3u);  // one new source after each of the three failed reads
  EXPECT_EQ(flaky.sources, 4);
  EXPECT_EQ(fetcher.in_flight_bytes(), 0u);
}

TEST(PullFetcher, AServerThatNeverComesBackIsReportedAfterTheRetryTime) {
  Flaky flaky;
  flaky.outage = -1;
  PageInbox inbox;
  PullFetcher fetcher(flaky.factory(), inbox, fast_retries(0.05));
  fetcher.request({schedule::PageKind::data, 1, 64}, kRange);
  EXPECT_TRUE(wait_for(inbox).empty());
  EXPECT_NE(inbox.error().find("connection refused"), std::string::npos) << inbox.error();
  EXPECT_GE(flaky.sources, 2);  // it did try again
}

TEST(PullFetcher, AFirstSourceThatCannotBeMadeIsReportedAtOnce) {
  Flaky flaky;
  flaky.first_fails = true;
  PageInbox inbox;
  PullFetcher fetcher(flaky.factory(), inbox, fast_retries(30.0));
  fetcher.request({schedule::PageKind::data, 1, 64}, kRange);
  EXPECT_TRUE(wait_for(inbox).empty());
  EXPECT_NE(inbox.error().find("cannot connect"), std::string::npos) << inbox.error();
  EXPECT_EQ(fetcher.reconnects(), 0u);
}
