#include "schedule/link_estimator.hpp"

#include <algorithm>

namespace lodstream::schedule {

LinkEstimator::LinkEstimator(LinkEstimatorOptions options) : options_(options) {}

void LinkEstimator::on_send(uint32_t sequence, uint64_t bytes, double now_s, bool app_limited) {
  // With nothing in flight, delivery restarts now: the idle gap must not count as slow delivery.
  if (sent_bytes_ == delivered_bytes_) delivered_time_ = now_s;
  in_flight_[sequence] = Sent{bytes, now_s, delivered_bytes_, delivered_time_, app_limited};
  sent_bytes_ += bytes;
}

// Keeps a monotonic deque of the samples that can still be the extreme of the window ending now: pushing a
// sample drops older ones it dominates, and samples older than `horizon` leave from the front.
void LinkEstimator::add_windowed(std::deque<Sample>& window, Sample s, double horizon, bool keep_max) {
  while (!window.empty() && (keep_max ? window.back().value <= s.value : window.back().value >= s.value))
    window.pop_back();
  window.push_back(s);
  while (window.front().time < s.time - horizon) window.pop_front();
}

void LinkEstimator::on_ack(uint32_t sequence, double now_s) {
  if (any_acked_ && sequence <= last_acked_) return;
  auto it = in_flight_.find(sequence);
  if (it == in_flight_.end()) return;
  // Everything up to `sequence` is delivered (acknowledgements are cumulative).
  // (Before the first acknowledgement the earlier sequences are unknown: scan what is in flight.)
  if (!any_acked_) {
    for (auto e = in_flight_.begin(); e != in_flight_.end();) {
      if (e->first < sequence) {
        delivered_bytes_ += e->second.bytes;
        e = in_flight_.erase(e);
      } else {
        ++e;
      }
    }
  }
  for (uint32_t s = any_acked_ ? last_acked_ + 1 : sequence; s < sequence; ++s) {
    auto earlier = in_flight_.find(s);
    if (earlier == in_flight_.end()) continue;
    delivered_bytes_ += earlier->second.bytes;
    in_flight_.erase(earlier);
  }
  const Sent sent = it->second;
  in_flight_.erase(it);
  delivered_bytes_ += sent.bytes;
  delivered_time_ = now_s;
  last_acked_ = sequence;
  any_acked_ = true;

  add_windowed(rtt_samples_, {now_s, now_s - sent.send_time}, options_.rtt_window_s, false);
  double interval = now_s - sent.delivered_time_at_send;
  if (interval <= 0.0) return;
  double rate = 8.0 * double(delivered_bytes_ - sent.delivered_at_send) / interval;
  if (!sent.app_limited || bandwidth_samples_.empty() || rate > bandwidth_samples_.front().value)
    add_windowed(bandwidth_samples_, {now_s, rate}, options_.bandwidth_window_s, true);
}

double LinkEstimator::bandwidth_bps() const {
  return bandwidth_samples_.empty() ? options_.initial_bandwidth_bps : bandwidth_samples_.front().value;
}

double LinkEstimator::rtt_s() const {
  return rtt_samples_.empty() ? options_.initial_rtt_s : rtt_samples_.front().value;
}

}  // namespace lodstream::schedule
