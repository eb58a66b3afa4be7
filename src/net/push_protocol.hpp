// The server side of a push session as a state machine without I/O (DESIGN.md, Serving and the wire; seed 003
// §5): it is fed the client's messages with the time they arrived and asked what to send now. The WebSocket
// session (push_session.hpp) is a thin shell around it; the benchmark's simulator drives the same class on a
// virtual clock over a simulated link.
//
// Protocol: the first message must be a Hello naming this package (answered by a Welcome); then ViewUpdates,
// Acks and finally a Bye or the end of the connection. Pages go out in the scheduler's order
// (schedule/page_scheduler.hpp): benefit per byte over the views predicted from the latest ViewUpdate
// (schedule/motion.hpp, horizons measured from the present plus half a round trip, the time a page sent now
// takes to arrive), index pages before the data pages that need their records; never a page the client holds
// (Hello's held runs, when its hash is this package's) or was sent and not released since (a Released
// message: the client's cache evicted it). At most `window_bdp` estimated
// bandwidth-delay products (schedule::LinkEstimator, fed by the acknowledgements) are in flight, at least
// `min_window_bytes` (`initial_window_bytes` before the first acknowledgement); so what waits, waits here,
// where a new view re-orders it: the plan is dropped on a ViewUpdate at least `replan_interval_s` (client
// time) after the view it was made from, and re-made from the new prediction. A plan covers `plan_windows`
// windows, so that acknowledgements do not each cost a plan (one cut per predicted view: on a 5.7M-triangle
// package through a 10 Mbit/s link, a plan per acknowledgement and per view update kept the server's core
// busy and the link a fifth used). Nothing is sent before the first ViewUpdate. When the scheduler has
// nothing to send (every predicted view's ideal cut sent) and `fill_when_idle` is set, the rest of the
// package follows in file order (index pages first), up to the client's cache budget: seed 003's "coffee
// break". Once a plan has nothing to send, none is made until something it depends on changes (a view
// with another pose, a release, a released page falling due): a converged client had cost its server a
// plan per acknowledgement and view update (elephant_5m, real push: server CPU 8.6 -> 7.4 s a run). The
// planned cuts keep to the triangles the client's cache budget affords (schedule/cache_budget.hpp). Pages the
// client released are sent again only when the scheduler picks them for a view, after a hold-off that doubles
// with each release of the page (schedule/release_backoff.hpp). A page the client keeps on disk (Hello's
// on_disk, a Released with on_disk) goes out as a Restore, a 24-byte message that has the client load it from
// its disk, instead of its bytes, and the plan prices it so (benefit per byte: a view coming back gets what
// the disk holds first); a Released without on_disk for such a page (the client could not load it) makes it
// due again at once, as bytes.
//
// Time is the caller's (seconds on any monotonic clock). Cost: a plan is one PageScheduler::next (one cut per
// predicted view) for a window's worth of pages.
#pragma once

#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "net/wire.hpp"
#include "package/reader.hpp"
#include "schedule/link_estimator.hpp"
#include "schedule/motion.hpp"
#include "schedule/package_records.hpp"
#include "schedule/page_scheduler.hpp"
#include "schedule/release_backoff.hpp"

namespace lodstream {

// What every session of one package shares: the reader and all node records. Immutable.
struct PushPackage {
  std::string name;  // NAME of ws://HOST:PORT/NAME
  std::shared_ptr<const package::PackageReader> reader;
  schedule::PackageRecords records;

  // Loads the records (one read of every index page). Throws lodstream::Error when the index is unreadable.
  PushPackage(std::string name, std::shared_ptr<const package::PackageReader> reader);
};

struct PushProtocolOptions {
  double ack_timeout_s = 30.0;          // pages in flight and nothing acknowledged for this long: the end
  size_t min_window_bytes = 64 * 1024;  // in flight at least this much
  // In flight at most this much until the first acknowledgement measures the link (then window_bdp
  // estimated bandwidth-delay products, which about double per round trip while the window is the limit, as
  // TCP's slow start). Measured on motorBike, gen:fly: at 10 Mbit/s 80 ms (2 BDP = 200 KB) 64 KiB left push
  // 120 KB behind the oracle at 1 s (to 0.95 in 1.67 s, AUC 0.952), 128 KiB 1.63 s / 0.954, 192 KiB 1.60 s /
  // 0.955; at 2 Mbit/s 150 ms (2 BDP = 75 KB) AUC 0.769 / 0.770 / 0.770: the first window only delays.
  size_t initial_window_bytes = 192 * 1024;
  double window_bdp = 2.0;  // in flight at most this many bandwidth-delay products
  double tau = 1.0;         // target pixel error of the client's cut
  schedule::PredictionHorizons horizons;
  bool fill_when_idle = true;
  double replan_interval_s = 0.1;  // a new view drops the plan when its sample is at least this much newer
  double plan_windows = 4.0;       // a plan covers this many windows' worth of pages
};

// A page the shell is to send now: read `page`'s stored bytes and send them as wire::Page{sequence,
// page.id, server_time_s, bytes, page.kind}; or, with `restore`, send wire::Restore{sequence, page.id,
// server_time_s} (a data page the client keeps on disk).
struct PageToSend {
  uint32_t sequence = 0;
  schedule::PageRef page;
  double server_time_s = 0.0;
  bool restore = false;
};

struct PushCounters {
  // pages_sent counts restores too; bytes_sent is page bytes only (what crossed the link as pages).
  uint64_t pages_sent = 0, bytes_sent = 0, index_pages_sent = 0, restores = 0, views = 0, acks = 0;
  uint64_t plans = 0;  // PageScheduler::next calls (the server's main cost)
};

class PushProtocol {
 public:
  PushProtocol(std::shared_ptr<const PushPackage> package, PushProtocolOptions options = {});

  // Feeds one message from the client, received at `now_s`. Returns what to send at once (the Welcome
  // answering the Hello), if anything. A Bye from the client ends the session (ended() is true). Throws
  // wire::WireError on a protocol violation (no Hello first, another package's name, a second Hello, a
  // message only servers send); the shell then sends a Bye with the reason and closes.
  std::optional<wire::Message> on_message(const wire::Message& message, double now_s);

  // The next page to send at `now_s`, or nothing while the window is full or nothing is left to send. The
  // page counts as sent (in flight, never sent again) from this call on.
  std::optional<PageToSend> next_page(double now_s);

  // The time by which an acknowledgement must arrive (pages in flight, nothing acknowledged since
  // ack_timeout_s before it), or +inf. check_timeout throws wire::WireError once `now_s` is past it.
  double ack_deadline() const;
  void check_timeout(double now_s) const;

  bool welcomed() const { return welcomed_; }
  bool ended() const { return ended_; }  // the client said Bye
  // Every page of the package has been sent or was held (nothing will ever be sent again).
  bool everything_sent() const { return remaining_ == 0; }
  const PushCounters& counters() const { return counters_; }
  const schedule::LinkEstimator& link() const { return link_; }
  const schedule::PageScheduler& scheduler() const { return scheduler_; }
  uint64_t window_bytes() const;

 private:
  void plan(double now_s, uint64_t bytes);
  void mark_sent(const schedule::PageRef& page);
  // Page `page` is (or is no longer) on the client's disk: sent as a Restore, priced as one by the plan.
  void set_on_disk(uint32_t page, bool on_disk);
  const package::PackageReader& reader() const { return *package_->reader; }

  std::shared_ptr<const PushPackage> package_;
  PushProtocolOptions options_;
  schedule::PageScheduler scheduler_;
  schedule::LinkEstimator link_;
  bool welcomed_ = false, ended_ = false;
  uint64_t cache_budget_ = 0;
  uint64_t triangle_budget_ = UINT64_MAX;  // of the planned cuts: what the client's cache affords
  // Decompressed bytes of the data pages the client holds as far as the server knows (held, sent, not
  // released): what its cache budget is spent on.
  uint64_t held_bytes_ = 0;
  std::vector<bool> released_;        // data pages the client let go: never sent again by the idle fill
  std::vector<bool> on_disk_;         // data pages the client keeps on disk: sent as a Restore
  schedule::ReleaseBackoff backoff_;  // when a released page may be planned again
  size_t remaining_ = 0;              // pages neither held nor sent
  std::optional<schedule::ViewSample> view_;
  double view_received_s_ = 0.0;
  std::optional<double> planned_view_s_;  // client time of the view sample the current plan was made from
  std::deque<schedule::PageRef> planned_;
  // The last plan had nothing to send (every predicted view's ideal cut sent, nothing to fill): no plan again
  // until the client reports another pose, releases a page, or a released page falls due.
  bool plan_converged_ = false;
  uint32_t sequence_ = 0, acked_ = 0;
  double last_progress_s_ = 0.0;  // last ack (or first send after an idle period)
  PushCounters counters_;
};

}  // namespace lodstream
