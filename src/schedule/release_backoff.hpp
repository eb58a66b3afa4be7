// When a page that a client's cache let go may be fetched or sent again. A page evicted over and over is one
// the cache cannot keep beside the rest of what the views need (pages are coarse: a 0.3 MB cache on a 0.9 MB
// package holds 8 of its 23 pages); fetching it again at once makes the link carry the same pages round and
// round (that run: 114 MB in 14 s for a partial picture). So each release of a page doubles its hold-off,
// from first_s up to max_s: a page evicted once because the view moved away comes back after first_s when
// the view returns, one that keeps being evicted is fetched O(log) times. Pure computation on the caller's
// clock; used by the push server (wire::Released) and the pull scheduler alike.
#pragma once

#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace lodstream::schedule {

class ReleaseBackoff {
 public:
  explicit ReleaseBackoff(double first_s = 0.25, double max_s = 8.0) : first_s_(first_s), max_s_(max_s) {}

  // Page `page` was let go at `now_s`: it is due again first_s * 2^(k-1) later (at most max_s), k = how many
  // times it was released. Cost: O(1).
  void released(uint32_t page, double now_s);
  // The released pages whose hold-off has ended by `now_s`, each once per release, sorted. Cost: O(pages
  // ever released) when one is due, O(1) otherwise.
  std::vector<uint32_t> due(double now_s);
  bool pending() const { return pending_ > 0; }
  // Whether some release is due by `now_s` (due() would return something). Cost: O(1).
  bool due_by(double now_s) const { return earliest_s_ <= now_s; }

 private:
  struct State {
    uint32_t releases = 0;
    double due_s = 0.0;
    bool pending = false;
  };
  double first_s_, max_s_;
  std::unordered_map<uint32_t, State> pages_;
  size_t pending_ = 0;
  double earliest_s_ = INFINITY;  // the earliest due_s of a pending page
};

}  // namespace lodstream::schedule
