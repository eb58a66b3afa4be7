#include "net/pull_fetcher.hpp"

#include <algorithm>

#include "core/error.hpp"

namespace lodstream {

PullFetcher::PullFetcher(SourceFactory make_source, PageInbox& inbox, PullOptions options)
    : inbox_(inbox), options_(options) {
  for (int i = 0; i < std::max(1, options_.connections); ++i)
    workers_.emplace_back([this, make_source] { work(make_source); });
}

PullFetcher::~PullFetcher() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& w : workers_) w.join();
}

double PullFetcher::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void PullFetcher::request(const schedule::PageRef& page, const package::Range& range) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back({page, range, now()});
    in_flight_ += range.size;
  }
  wake_.notify_all();  // a worker waiting out a back-off must not take the only notification
}

uint64_t PullFetcher::in_flight_bytes() const {
  std::lock_guard lock(mutex_);
  return in_flight_;
}

double PullFetcher::bandwidth_bps() const {
  std::lock_guard lock(mutex_);
  return best_rate_bps_;
}

double PullFetcher::rtt_s() const {
  std::lock_guard lock(mutex_);
  return min_rtt_s_;
}

uint64_t PullFetcher::reconnects() const {
  std::lock_guard lock(mutex_);
  return reconnects_;
}

uint64_t PullFetcher::window_bytes() const {
  std::lock_guard lock(mutex_);
  const double bdp = best_rate_bps_ / 8.0 * min_rtt_s_;
  return uint64_t(std::max(double(options_.min_window_bytes), options_.window_bdp * bdp));
}

bool PullFetcher::read_with_retry(const SourceFactory& make_source,
                                  std::shared_ptr<const package::ByteSource>& source, const Request& r,
                                  std::vector<uint8_t>& out) {
  double wait_s = options_.first_backoff_s, failing_since = -1.0;
  for (;;) {
    try {
      if (!source) {
        source = make_source();
        std::lock_guard lock(mutex_);
        ++reconnects_;
      }
      source->read(r.range.offset, out);
      return true;
    } catch (const Error& e) {
      source.reset();
      const double t = now();
      if (failing_since < 0.0) failing_since = t;
      if (t - failing_since >= options_.retry_s) {
        inbox_.fail(e.what());
        return false;
      }
    }
    std::unique_lock lock(mutex_);
    if (wake_.wait_for(lock, std::chrono::duration<double>(wait_s), [&] { return stop_; })) return false;
    wait_s = std::min(2.0 * wait_s, options_.max_backoff_s);
  }
}

void PullFetcher::work(const SourceFactory& make_source) {
  std::shared_ptr<const package::ByteSource> source;
  try {
    source = make_source();
  } catch (const Error& e) {
    inbox_.fail(e.what());
    return;
  }
  for (;;) {
    Request r;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      r = queue_.front();
      queue_.pop_front();
    }
    ArrivedPage arrived{r.page, std::vector<uint8_t>(r.range.size)};
    if (!read_with_retry(make_source, source, r, arrived.bytes)) return;
    {
      std::lock_guard lock(mutex_);
      const double t = now();
      in_flight_ -= r.range.size;
      const double took = t - r.sent_s;
      if (min_rtt_s_ == 0.0 || took < min_rtt_s_) min_rtt_s_ = took;
      // Delivery rate over the window (bytes completed in it / its span).
      completed_.push_back({t, r.range.size});
      while (completed_.size() > 1 && completed_.front().first < t - options_.bandwidth_window_s)
        completed_.pop_front();
      uint64_t bytes = 0;
      for (auto& c : completed_) bytes += c.second;
      const double span = std::max(t - completed_.front().first, took);
      const double rate = span > 0.0 ? 8.0 * double(bytes) / span : 0.0;
      if (rate > best_rate_bps_ || t - best_rate_time_ > options_.bandwidth_window_s) {
        best_rate_bps_ = rate;
        best_rate_time_ = t;
      }
    }
    // After the bookkeeping: a consumer woken by the inbox sees the window this page freed.
    inbox_.put(std::move(arrived));
  }
}

}  // namespace lodstream
