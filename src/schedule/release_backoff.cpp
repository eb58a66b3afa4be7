#include "schedule/release_backoff.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream::schedule {

void ReleaseBackoff::released(uint32_t page, double now_s) {
  State& s = pages_[page];
  ++s.releases;
  s.due_s = now_s + std::min(max_s_, std::ldexp(first_s_, int(std::min<uint32_t>(s.releases - 1, 30))));
  if (!s.pending) s.pending = true, ++pending_;
  earliest_s_ = std::min(earliest_s_, s.due_s);
}

std::vector<uint32_t> ReleaseBackoff::due(double now_s) {
  std::vector<uint32_t> pages;
  if (!due_by(now_s)) return pages;
  earliest_s_ = INFINITY;
  for (auto& [page, s] : pages_) {
    if (!s.pending) continue;
    if (s.due_s <= now_s) {
      s.pending = false;
      --pending_;
      pages.push_back(page);
    } else {
      earliest_s_ = std::min(earliest_s_, s.due_s);
    }
  }
  std::sort(pages.begin(), pages.end());
  return pages;
}

}  // namespace lodstream::schedule
