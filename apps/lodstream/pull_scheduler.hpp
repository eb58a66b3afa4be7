// The pulling client's scheduler on a thread of its own (issue 5: streaming never blocks a frame; the frame
// thread does not pay for scheduling). The frame thread publishes its latest view sample; this thread decides
// what to fetch (PageScheduler over the sample's predicted views, or the sse-pull order) and keeps the
// PullFetcher's request window full.
//
// Ownership, so that nothing is shared without a lock: this object's thread alone owns a copy of the client's
// PackageReader (the node records the scheduler sees: index pages are installed into it here) and the
// PageScheduler with its held set (pages arrived, requested or planned; pages the frame thread's cache
// evicted are reported through evicted() and become schedulable again after a hold-off that doubles with each
// eviction of the page: schedule/release_backoff.hpp). The frame thread owns the
// ClientPackage it installs arrived pages into. The fetcher's threads relay arrived pages as soon as they are
// read (the inbox's listener): into the frame thread's inbox, and for index pages a copy into this object's
// slot; then they request the next planned pages while the window has room. The threads share only that
// mutex-protected slot (latest view sample, evicted pages, index pages to install, the planned pages not
// requested yet, a wake-up flag) and the inboxes (thread-safe).
//
// Plans (one PageScheduler::next or next_sse call each) look kPlanAhead windows ahead: the window's room is
// requested at once, the rest in the plan's order as arrivals free the window, on the fetcher's threads, so
// that the link stays busy while this thread plans. It plans only when the window has room or nothing is
// left to request, and then when an index page arrived (new records), an evicted page's hold-off ended, the
// view moved and the last plan is at least kReplanInterval older in the samples' own time, or the last plan's
// pages are all requested and it chose anything (there may be more to fetch). It sleeps otherwise, woken by
// publish(), evicted() and every arrival: no polling. A plan costs one select_cut per predicted view;
// bounding their rate keeps clients that share a few cores from spending them on plans.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
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
#include "schedule/release_backoff.hpp"

namespace lodstream::cli {

// Pull orders: `benefit` (PageScheduler::next, benefit per byte over the predicted views) or `sse`
// (PageScheduler::next_sse over the current view: the sse-pull baseline).
enum class PullOrder { benefit, sse };

class PullScheduler {
 public:
  // Seconds of view-sample time between two plans made for a moved view alone.
  static constexpr double kReplanInterval = 0.1;
  // How many request windows of pages a plan chooses.
  static constexpr uint64_t kPlanAhead = 4;

  // `reader`: a copy of the client's reader (its root index read; index pages added here). Starts the
  // fetcher (over `make_source`, with `fetch`) and this object's thread; arrived pages and the transport's
  // failure go to `frames` (which must outlive this object). Nothing is fetched before the first publish();
  // `held` pages (restored from a disk cache) are never fetched.
  PullScheduler(package::PackageReader reader, PullFetcher::SourceFactory make_source, PullOptions fetch,
                PageInbox& frames, PullOrder order, schedule::CutOptions cut,
                std::span<const schedule::PageRef> held = {});
  // Stops this thread, then the fetcher (after the reads under way).
  ~PullScheduler();
  PullScheduler(const PullScheduler&) = delete;
  PullScheduler& operator=(const PullScheduler&) = delete;

  // Any thread (the frame thread): the latest view (it replaces one not yet planned for); pages the client's
  // cache evicted. O(1) and O(pages) under the slot's mutex.
  void publish(const schedule::ViewSample& latest);
  void evicted(std::span<const uint32_t> pages);

  // Plans made so far (each one scheduler call). Any thread.
  uint64_t plans() const;
  // The fetcher's reconnections (PullFetcher::reconnects). Any thread.
  uint64_t reconnects() const { return fetcher_.reconnects(); }

 private:
  void run();
  // The fetcher's threads: hands what arrived on (see above), requests planned pages, wakes this thread.
  void relay();
  // Requests planned pages while the window has room. Any thread, with mutex_ held.
  void issue();

  // This thread only.
  package::PackageReader reader_;
  runtime::PageCache no_pages_{0};  // the scheduler reads records only (availability is its held set)
  runtime::PackageNodes records_;   // over reader_
  schedule::PageScheduler scheduler_;
  PageInbox& frames_;
  const PullOrder order_;
  const schedule::CutOptions cut_;

  // The slot shared with the frame thread and the fetcher's threads.
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool woken_ = false, stop_ = false;
  std::optional<schedule::ViewSample> latest_;
  std::vector<uint32_t> evicted_;
  schedule::ReleaseBackoff backoff_;      // scheduler thread: when an evicted page may be fetched again
  std::vector<ArrivedPage> index_pages_;  // arrived, for reader_
  std::deque<schedule::PageRef> ahead_;   // planned (held), not requested yet, in plan order
  std::string error_;                     // the transport's failure, once
  uint64_t plans_ = 0;

  PageInbox fetched_{[this] { relay(); }};  // the fetcher's
  PullFetcher fetcher_;                     // after fetched_ and the slot: destroyed before them
  std::thread thread_;
};

}  // namespace lodstream::cli
