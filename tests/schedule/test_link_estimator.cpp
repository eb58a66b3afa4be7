#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "schedule/link_estimator.hpp"

using namespace lodstream::schedule;

namespace {
// A sender that keeps about two estimated bandwidth-delay products in flight over a bottleneck of `bps` with
// `rtt` (half each way; acknowledgements are small and only delayed), from time `from` to `to`. Events are
// (time → acknowledged sequence), processed in time order: a small discrete-event simulation.
struct Path {
  double bps, rtt;
};

void run(LinkEstimator& estimator, const Path& path, double from, double to, uint32_t& sequence,
         double& busy_until, std::multimap<double, uint32_t>& acks) {
  const uint64_t message = 16 * 1024;
  double now = from;
  while (now < to) {
    while (double(estimator.bytes_in_flight()) < std::max(2.0 * estimator.bdp_bytes(), 64.0 * 1024)) {
      ++sequence;
      estimator.on_send(sequence, message, now);
      busy_until = std::max(busy_until, now) + 8.0 * double(message) / path.bps;
      acks.emplace(busy_until + path.rtt, sequence);  // arrives after rtt/2, acknowledged after another rtt/2
    }
    // Advance to the next acknowledgement.
    auto next = acks.begin();
    now = next->first;
    estimator.on_ack(next->second, now);
    acks.erase(next);
  }
}
}  // namespace

TEST(LinkEstimator, ConvergesToTheBottleneckAndTheRoundTrip) {
  LinkEstimator estimator;
  uint32_t sequence = 0;
  double busy = 0;
  std::multimap<double, uint32_t> acks;
  run(estimator, {10e6, 0.08}, 0.0, 3.0, sequence, busy, acks);
  EXPECT_NEAR(estimator.bandwidth_bps(), 10e6, 1e6);
  // The round trip of one message includes its own transmission at the bottleneck (16 KB at 10 Mbit/s).
  const double rtt = 0.08 + 8.0 * 16384 / 10e6;
  EXPECT_NEAR(estimator.rtt_s(), rtt, 0.002);
  EXPECT_NEAR(estimator.bdp_bytes(), 10e6 / 8 * rtt, 0.1 * 10e6 / 8 * rtt);
}

TEST(LinkEstimator, FollowsABandwidthDropWithinOneWindow) {
  LinkEstimatorOptions options;
  options.bandwidth_window_s = 2.0;
  LinkEstimator estimator(options);
  uint32_t sequence = 0;
  double busy = 0;
  std::multimap<double, uint32_t> acks;
  run(estimator, {10e6, 0.05}, 0.0, 3.0, sequence, busy, acks);
  EXPECT_NEAR(estimator.bandwidth_bps(), 10e6, 1e6);
  // The path halves (Teler & Lischinski's test T6): within one window plus the queue's drain, the estimate
  // follows.
  run(estimator, {5e6, 0.05}, 3.0, 3.0 + 2.0 + 1.0, sequence, busy, acks);
  EXPECT_NEAR(estimator.bandwidth_bps(), 5e6, 0.5e6);
}

TEST(LinkEstimator, IdleGapsAndAppLimitedSamplesDoNotLowerTheEstimate) {
  LinkEstimator estimator;
  uint32_t sequence = 0;
  double busy = 0;
  std::multimap<double, uint32_t> acks;
  run(estimator, {8e6, 0.05}, 0.0, 2.0, sequence, busy, acks);
  while (!acks.empty()) {  // drain what is in flight
    estimator.on_ack(acks.begin()->second, acks.begin()->first);
    acks.erase(acks.begin());
  }
  EXPECT_EQ(estimator.bytes_in_flight(), 0u);
  double before = estimator.bandwidth_bps();
  EXPECT_NEAR(before, 8e6, 0.8e6);
  // After an idle second, a lone small message the sender had nothing to follow with: its slow-looking rate
  // sample (100 bytes in one round trip) is ignored, and the idle time is not counted as delivery time.
  estimator.on_send(++sequence, 100, 3.0, true);
  estimator.on_ack(sequence, 3.05);
  EXPECT_DOUBLE_EQ(estimator.bandwidth_bps(), before);
  // Duplicate and unknown acknowledgements change nothing.
  estimator.on_ack(sequence, 4.0);
  estimator.on_ack(sequence + 50, 4.0);
  EXPECT_EQ(estimator.bytes_in_flight(), 0u);
  EXPECT_DOUBLE_EQ(estimator.bandwidth_bps(), before);
}

TEST(LinkEstimator, TheFirstAcknowledgementIsCumulativeToo) {
  LinkEstimator e;
  e.on_send(1, 1000, 0.0);
  e.on_send(2, 1000, 0.0);
  e.on_send(3, 500, 0.0);
  EXPECT_EQ(e.bytes_in_flight(), 2500u);
  e.on_ack(2, 0.1);  // covers 1 and 2
  EXPECT_EQ(e.bytes_in_flight(), 500u);
  e.on_ack(3, 0.2);
  EXPECT_EQ(e.bytes_in_flight(), 0u);
}
