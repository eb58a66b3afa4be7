// Link model: when bytes sent into one direction of an emulated link come out of it (DESIGN.md, Link
// emulation). A token bucket serializes bytes at the link's bandwidth (a bottleneck with no burst beyond one
// packet), then a delay line adds half the round-trip time plus jitter. Delivery order is preserved, as on
// one TCP path. Pure computation on caller-supplied times, so the real proxy (`lodstream link`) and the
// benchmark's simulated link share it. Cost: O(1) per packet.
#pragma once

#include <cstdint>
#include <random>
#include <string>

namespace lodstream {

struct LinkSettings {
  double bandwidth_bps = 10e6;  // bits per second, each direction
  double rtt_s = 0.08;          // round-trip time: each direction adds half
  double jitter_s = 0.0;        // each packet's one-way delay varies uniformly within ±jitter (order kept)
  uint64_t seed = 1;            // jitter is pseudo-random and reproducible
};

// Parses "10mbit", "500kbit", "1gbit", "2000000bit" or a plain number of bits per second; throws
// lodstream::Error naming `option` otherwise.
double parse_bandwidth(const std::string& text, const std::string& option);

// Parses "80ms", "0.08s", "500us" or a plain number of milliseconds; throws lodstream::Error naming `option`.
double parse_duration(const std::string& text, const std::string& option);

class LinkDirection {
 public:
  explicit LinkDirection(const LinkSettings& settings);

  // `bytes` enter the link at time `now_s` (seconds on the caller's clock); returns when their last byte
  // leaves the far end. Serialization: t_tx = max(now, busy_until) + 8·bytes / bandwidth; delivery: t_tx +
  // rtt/2 + jitter, never before the previous delivery.
  double send(double now_s, size_t bytes);

  // Time at which the bottleneck has transmitted everything sent so far (≤ now when it is idle).
  double busy_until() const { return busy_until_; }

 private:
  LinkSettings settings_;
  double busy_until_ = 0.0;
  double last_delivery_ = 0.0;
  std::mt19937_64 random_;
};

}  // namespace lodstream
