// Pull transport of a client (DESIGN.md, Serving and the wire: "the client runs the same scheduler and
// fetches page ranges itself, with a request window sized from the measured bandwidth-delay product; it works
// against any static HTTP server"): `connections` worker threads, each with its own ByteSource (an
// HttpSource: one keep-alive connection; or a local file), read the requested pages' byte ranges in request
// order and leave them in a PageInbox (after updating in_flight_bytes(), so that a consumer the inbox wakes
// sees the room the page freed). The caller (one scheduling thread, e.g. the view's PullScheduler) asks for
// pages while in_flight_bytes() < window_bytes(); every member function is thread-safe.
//
// Window = max(min_window_bytes, window_bdp * bandwidth * rtt): bandwidth = the largest rate of delivered
// bytes over the last `bandwidth_window_s` (sampled per completed request: bytes completed in the window /
// its span), rtt = the smallest time any request took (request to last byte: the round trip plus one page's
// transfer, an upper bound of the path's RTT). A failed read (the server went away or restarted) is tried
// again on a new source (make_source) after a back-off that doubles from first_backoff_s to max_backoff_s,
// the request kept, so that the client reconnects by itself while its frames draw what it holds (issue 5);
// after `retry_s` of failures it is reported through the inbox (fail()) and ends that worker. A failure to
// make the first source is reported at once.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "net/page_inbox.hpp"
#include "package/byte_source.hpp"
#include "package/index.hpp"

namespace lodstream {

struct PullOptions {
  int connections = 4;
  size_t min_window_bytes = 256 * 1024;
  double window_bdp = 2.0;
  double bandwidth_window_s = 1.0;
  double first_backoff_s = 0.1, max_backoff_s = 2.0;
  double retry_s = 20.0;
};

class PullFetcher {
 public:
  using SourceFactory = std::function<std::shared_ptr<const package::ByteSource>()>;

  // Starts the workers; each calls `make_source` once (in its thread). `inbox` must outlive the fetcher.
  PullFetcher(SourceFactory make_source, PageInbox& inbox, PullOptions options = {});
  ~PullFetcher();  // stops the workers after their current read
  PullFetcher(const PullFetcher&) = delete;
  PullFetcher& operator=(const PullFetcher&) = delete;

  // Queues a read of `range` (the page's stored bytes).
  void request(const schedule::PageRef& page, const package::Range& range);
  uint64_t in_flight_bytes() const;
  uint64_t window_bytes() const;
  double bandwidth_bps() const;
  double rtt_s() const;
  // Sources made again after a failed read (successful reconnections), over all workers.
  uint64_t reconnects() const;

 private:
  struct Request {
    schedule::PageRef page;
    package::Range range;
    double sent_s;
  };
  void work(const SourceFactory& make_source);
  // Reads `r` into `out` through `source`, making a new source after each failure (back-off, then retry);
  // false when the fetcher stops or retry_s ran out (then reported).
  bool read_with_retry(const SourceFactory& make_source, std::shared_ptr<const package::ByteSource>& source,
                       const Request& r, std::vector<uint8_t>& out);
  double now() const;

  PageInbox& inbox_;
  PullOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Request> queue_;
  bool stop_ = false;
  uint64_t in_flight_ = 0, reconnects_ = 0;
  double min_rtt_s_ = 0.0;
  std::deque<std::pair<double, uint64_t>> completed_;  // (time, bytes) within the bandwidth window
  double best_rate_bps_ = 0.0, best_rate_time_ = -1e9;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::vector<std::thread> workers_;
};

}  // namespace lodstream
