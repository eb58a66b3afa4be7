// Link estimator: the sender's view of a path's bandwidth and round-trip time, from acknowledgements
// (DESIGN.md, Serving and the wire: "the client acknowledges what it received; the server estimates bandwidth
// and RTT").
//
// Delivery-rate sampling as BBR does it (Cardwell et al., "BBR: congestion-based congestion control", 2016):
// when a message is sent the estimator stamps it with how much had been delivered so far and when; when it is
// acknowledged, rate = (delivered now − delivered at send) / (now − delivery time at send). That ratio
// measures the bottleneck even when the sender keeps only a window in flight. Bandwidth = the largest sample
// of the last `bandwidth_window_s` (Teler & Lischinski's "average bandwidth over a recent time window", made
// robust to gaps in sending: samples taken while the sender had nothing to send count only when they raise
// the estimate). RTT = the smallest sample of the last `rtt_window_s`. Pure computation: times come from the
// caller's clock, so the same code runs in the server, the client and the simulator. Cost: O(1) amortized per
// message.
#pragma once

#include <cstdint>
#include <deque>
#include <unordered_map>

namespace lodstream::schedule {

struct LinkEstimatorOptions {
  double bandwidth_window_s = 2.0;
  double rtt_window_s = 10.0;
  double initial_bandwidth_bps = 1e6;  // until the first sample
  double initial_rtt_s = 0.1;
};

class LinkEstimator {
 public:
  explicit LinkEstimator(LinkEstimatorOptions options = {});

  // Message `sequence` (strictly increasing) of `bytes` leaves at `now_s`. `app_limited`: the sender had
  // nothing more to send, so the samples it yields may understate the bandwidth.
  void on_send(uint32_t sequence, uint64_t bytes, double now_s, bool app_limited = false);

  // Every message up to and including `sequence` arrived (a cumulative acknowledgement) as of `now_s`.
  // Unknown or already acknowledged sequences are ignored.
  void on_ack(uint32_t sequence, double now_s);

  // Whether an acknowledgement has given a bandwidth sample yet (before it, bandwidth_bps() is the initial
  // guess).
  bool measured() const { return !bandwidth_samples_.empty(); }
  double bandwidth_bps() const;  // bits per second
  double rtt_s() const;
  // Bandwidth-delay product in bytes: what should be in flight to keep the path busy and no more.
  double bdp_bytes() const { return bandwidth_bps() / 8.0 * rtt_s(); }
  uint64_t bytes_in_flight() const { return sent_bytes_ - delivered_bytes_; }

 private:
  struct Sent {
    uint64_t bytes;
    double send_time;
    uint64_t delivered_at_send;
    double delivered_time_at_send;
    bool app_limited;
  };
  struct Sample {
    double time, value;
  };
  static void add_windowed(std::deque<Sample>& window, Sample s, double horizon, bool keep_max);

  LinkEstimatorOptions options_;
  std::unordered_map<uint32_t, Sent> in_flight_;
  uint32_t last_acked_ = 0;
  bool any_acked_ = false;
  uint64_t sent_bytes_ = 0, delivered_bytes_ = 0;
  double delivered_time_ = 0.0;
  std::deque<Sample> bandwidth_samples_;  // decreasing values: the front is the window's maximum
  std::deque<Sample> rtt_samples_;        // increasing values: the front is the window's minimum
};

}  // namespace lodstream::schedule
