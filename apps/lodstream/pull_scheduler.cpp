#include "pull_scheduler.hpp"

#include <deque>

#include "core/error.hpp"

namespace lodstream::cli {

using schedule::PageKind;

namespace {

// Whether two samples differ in pose or motion (their times aside).
bool moved(const schedule::ViewSample& a, const schedule::ViewSample& b) {
  return a.eye != b.eye || a.forward != b.forward || a.up != b.up || a.velocity != b.velocity ||
         a.angular_velocity != b.angular_velocity || a.fov_y_radians != b.fov_y_radians ||
         a.width != b.width || a.height != b.height;
}

}  // namespace

PullScheduler::PullScheduler(package::PackageReader reader, PullFetcher::SourceFactory make_source,
                             PullOptions fetch, PageInbox& frames, PullOrder order, double tau)
    : reader_(std::move(reader)),
      records_(reader_, no_pages_),
      scheduler_(reader_.root()),
      frames_(frames),
      order_(order),
      tau_(tau),
      fetcher_(std::move(make_source), fetched_, fetch) {
  thread_ = std::thread([this] { run(); });
}

PullScheduler::~PullScheduler() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void PullScheduler::publish(const schedule::ViewSample& latest) {
  {
    std::lock_guard lock(mutex_);
    latest_ = latest;
    woken_ = true;
  }
  wake_.notify_all();
}

void PullScheduler::evicted(std::span<const uint32_t> pages) {
  if (pages.empty()) return;
  {
    std::lock_guard lock(mutex_);
    evicted_.insert(evicted_.end(), pages.begin(), pages.end());
    woken_ = true;
  }
  wake_.notify_all();
}

uint64_t PullScheduler::plans() const {
  std::lock_guard lock(mutex_);
  return plans_;
}

void PullScheduler::relay() {
  std::vector<ArrivedPage> index;
  for (ArrivedPage& a : fetched_.take()) {
    if (a.page.kind == PageKind::index) index.push_back(a);
    frames_.put(std::move(a));
  }
  const std::string error = fetched_.error();
  if (!error.empty()) frames_.fail(error);
  {
    std::lock_guard lock(mutex_);
    for (ArrivedPage& a : index) index_pages_.push_back(std::move(a));
    if (!error.empty()) error_ = error;
    woken_ = true;
  }
  wake_.notify_all();
}

void PullScheduler::run() {
  const package::RootIndex& root = reader_.root();
  std::optional<schedule::ViewSample> planned;  // the sample of the last plan
  bool room_left = false;               // the last plan reached its byte limit: there may be more to fetch
  std::deque<schedule::PageRef> ahead;  // the last plan's pages not requested yet, in its order
  for (;;) {
    std::optional<schedule::ViewSample> sample;
    std::vector<uint32_t> evicted;
    std::vector<ArrivedPage> index;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || woken_; });
      if (stop_ || !error_.empty()) return;
      woken_ = false;
      sample = latest_;
      evicted.swap(evicted_);
      index.swap(index_pages_);
    }
    for (uint32_t page : evicted) scheduler_.set_held(PageKind::data, page, false);
    try {
      for (const ArrivedPage& a : index) reader_.add_index_page(a.page.id, a.bytes);
    } catch (const Error& e) {
      frames_.fail(e.what());  // the frame thread's install throws the same
      return;
    }
    if (!sample) continue;
    uint64_t in_flight = fetcher_.in_flight_bytes();
    const uint64_t window = fetcher_.window_bytes();
    if (in_flight >= window) continue;
    const bool view_due =
        !planned || (moved(*sample, *planned) && sample->time_s - planned->time_s >= kReplanInterval);
    const bool more = ahead.empty() && room_left;
    if (view_due || more || !index.empty() || !evicted.empty()) {
      // A plan for kPlanAhead windows: the window's room is requested now, the rest as it frees up.
      planned = sample;
      const schedule::ScheduleOptions options{tau_, kPlanAhead * window, SIZE_MAX};
      const auto predicted = schedule::predicted_views(*sample, 0.0);
      const std::vector<schedule::PageRef> pages =
          order_ == PullOrder::sse
              ? scheduler_.next_sse(reader_.scene(), records_, predicted[0].view, options)
              : scheduler_.next(reader_.scene(), records_, predicted, options);
      uint64_t bytes = 0;
      for (const schedule::PageRef& p : pages) bytes += p.bytes;
      room_left = !pages.empty() && bytes >= options.max_bytes;
      ahead.assign(pages.begin(), pages.end());
      std::lock_guard lock(mutex_);
      ++plans_;
    }
    // Requests in plan order while the window has room (at least one page when it has any).
    while (!ahead.empty() && in_flight < window) {
      const schedule::PageRef p = ahead.front();
      ahead.pop_front();
      scheduler_.set_held(p.kind, p.id);
      fetcher_.request(p, p.kind == PageKind::data ? root.pages[p.id] : root.index_pages[p.id].range);
      in_flight += p.bytes;
    }
  }
}

}  // namespace lodstream::cli
