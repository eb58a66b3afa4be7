// The pulling client's scheduler on a thread of its own (issue 5: streaming never blocks a frame; the frame
// thread does not pay for scheduling). The frame thread publishes its latest view sample; this thread decides
// what to fetch (PageScheduler over the sample's predicted views, or the sse-pull order), keeps the
// PullFetcher's request window full, and relays what arrives to the frame thread's inbox.
//
// Ownership, so that nothing is shared without a lock: this object's thread alone owns a copy of the client's
// PackageReader (the node records the scheduler sees: index pages are installed into it here as they arrive,
// before they are relayed) and the PageScheduler with its held set (pages arrived or requested; pages the
// frame thread's cache evicted are reported through evicted() and become schedulable again). The frame
// thread owns the ClientPackage it installs relayed pages into. The two share only the mutex-protected slot
// below (the latest view sample, the evicted pages, a wake-up flag) and the inboxes (thread-safe).
//
// When it plans (one PageScheduler::next or next_sse call, for as many bytes as the window has room): when
// the window has room and something has changed since the last plan (a new view sample, an index page
// arrived, a page evicted) or the last plan filled the room it had (there may be more to fetch). It sleeps
// otherwise, woken by publish(), evicted() and every arrival (the fetcher's inbox listener): no polling.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "net/page_inbox.hpp"
#include "net/pull_fetcher.hpp"
#include "package/reader.hpp"
#include "runtime/cache.hpp"
#include "runtime/package_nodes.hpp"
#include "schedule/motion.hpp"
#include "schedule/page_scheduler.hpp"

namespace lodstream::cli {

// Pull orders: `benefit` (PageScheduler::next, benefit per byte over the predicted views) or `sse`
// (PageScheduler::next_sse over the current view: the sse-pull baseline).
enum class PullOrder { benefit, sse };

class PullScheduler {
 public:
  // `reader`: a copy of the client's reader (its root index read; index pages added here). Starts the
  // fetcher (over `make_source`, with `fetch`) and this object's thread; arrived pages and the transport's
  // failure go to `frames` (which must outlive this object). Nothing is fetched before the first publish();
  // `held` pages (restored from a disk cache) are never fetched.
  PullScheduler(package::PackageReader reader, PullFetcher::SourceFactory make_source, PullOptions fetch,
                PageInbox& frames, PullOrder order, double tau, std::span<const schedule::PageRef> held = {});
  // Stops this thread, then the fetcher (after the reads under way).
  ~PullScheduler();
  PullScheduler(const PullScheduler&) = delete;
  PullScheduler& operator=(const PullScheduler&) = delete;

  // Any thread (the frame thread): the latest view (it replaces one not yet planned for); pages the client's
  // cache evicted. O(1) and O(pages) under the slot's mutex.
  void publish(const schedule::ViewSample& latest);
  void evicted(std::span<const uint32_t> pages);

  // Plans made so far (each one scheduler call), for reports. Any thread.
  uint64_t plans() const;
  // The fetcher's reconnections (PullFetcher::reconnects). Any thread.
  uint64_t reconnects() const { return fetcher_.reconnects(); }

 private:
  void run();
  // Relays what arrived to `frames_`, installing index pages into `reader_` first; true if one was an index
  // page. This thread.
  bool relay();
  void wake();

  // This thread only.
  package::PackageReader reader_;
  runtime::PageCache no_pages_{0};  // the scheduler reads records only (availability is its held set)
  runtime::PackageNodes records_;   // over reader_
  schedule::PageScheduler scheduler_;
  PageInbox& frames_;
  const PullOrder order_;
  const double tau_;

  // The slot shared with the frame thread.
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool woken_ = false, stop_ = false;
  std::optional<schedule::ViewSample> latest_;
  uint64_t view_generation_ = 0;
  std::vector<uint32_t> evicted_;
  uint64_t plans_ = 0;

  PageInbox fetched_{[this] { wake(); }};  // the fetcher's, relayed by this thread
  PullFetcher fetcher_;                    // after fetched_ and the slot: destroyed before them
  std::thread thread_;
};

}  // namespace lodstream::cli
