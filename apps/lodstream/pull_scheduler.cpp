#include "pull_scheduler.hpp"

#include <utility>

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
                             PullOptions fetch, PageInbox& frames, PullOrder order, schedule::CutOptions cut,
                             std::span<const schedule::PageRef> held)
    : reader_(std::move(reader)),
      records_(reader_, no_pages_),
      scheduler_(reader_.root()),
      frames_(frames),
      order_(order),
      cut_(cut),
      fetcher_(std::move(make_source), fetched_, fetch) {
  for (const schedule::PageRef& p : held) scheduler_.set_held(p.kind, p.id);
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
    issue();
  }
  wake_.notify_all();
}

void PullScheduler::issue() {
  uint64_t in_flight = fetcher_.in_flight_bytes();
  const uint64_t window = fetcher_.window_bytes();
  const package::RootIndex& root = reader_.root();  // immutable: read from any thread
  while (!ahead_.empty() && in_flight < window) {
    const schedule::PageRef p = ahead_.front();
    ahead_.pop_front();
    fetcher_.request(p, p.kind == PageKind::data ? root.pages[p.id] : root.index_pages[p.id].range);
    in_flight += p.bytes;
  }
}

void PullScheduler::run() {
  std::optional<schedule::ViewSample> planned;  // the sample of the last plan
  // The last plan chose something: there may be more to fetch once its pages are requested. (Not "it reached
  // its byte limit": the greedy order stops short of the limit when the next page does not fit, and a still
  // camera with every index page arrived would then never plan again.)
  bool room_left = false;
  for (;;) {
    std::optional<schedule::ViewSample> sample;
    std::vector<uint32_t> evicted;
    std::vector<ArrivedPage> index;
    bool ahead_empty = true;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || woken_; });
      if (stop_ || !error_.empty()) return;
      woken_ = false;
      sample = latest_;
      evicted.swap(evicted_);
      index.swap(index_pages_);
      ahead_empty = ahead_.empty();
    }
    const double now_s = sample ? sample->time_s : 0.0;
    for (uint32_t page : evicted) backoff_.released(page, now_s);
    const std::vector<uint32_t> due = backoff_.due(now_s);
    for (uint32_t page : due) scheduler_.set_held(PageKind::data, page, false);
    try {
      for (const ArrivedPage& a : index) reader_.add_index_page(a.page.id, a.bytes);
    } catch (const Error& e) {
      frames_.fail(e.what());  // the frame thread's install throws the same
      return;
    }
    if (!sample) continue;
    const uint64_t window = fetcher_.window_bytes();
    if (fetcher_.in_flight_bytes() >= window && !ahead_empty) continue;
    const bool view_due =
        !planned || (moved(*sample, *planned) && sample->time_s - planned->time_s >= kReplanInterval);
    const bool more = ahead_empty && room_left;
    if (!(view_due || more || !index.empty() || !due.empty())) continue;

    // A plan for kPlanAhead windows, made while the fetcher's threads go on requesting the last plan's pages
    // (held, so not chosen again). Its pages go first; what is left of the last plan follows, up to
    // kPlanAhead windows in all, and the rest is not held any more (the next plan may choose it again).
    planned = sample;
    const schedule::ScheduleOptions options{cut_.tau, kPlanAhead * window, SIZE_MAX, cut_.triangle_budget};
    const auto predicted = schedule::predicted_views(*sample, 0.0);
    const std::vector<schedule::PageRef> pages =
        order_ == PullOrder::sse ? scheduler_.next_sse(reader_.scene(), records_, predicted[0].view, options)
                                 : scheduler_.next(reader_.scene(), records_, predicted, options);
    uint64_t bytes = 0;
    for (const schedule::PageRef& p : pages) {
      scheduler_.set_held(p.kind, p.id);
      bytes += p.bytes;
    }
    room_left = !pages.empty();
    std::vector<schedule::PageRef> dropped;
    {
      std::lock_guard lock(mutex_);
      std::deque<schedule::PageRef> left = std::exchange(ahead_, {pages.begin(), pages.end()});
      for (const schedule::PageRef& p : left) {
        if (bytes + p.bytes <= options.max_bytes) {
          ahead_.push_back(p);
          bytes += p.bytes;
        } else {
          dropped.push_back(p);
        }
      }
      ++plans_;
      issue();
    }
    for (const schedule::PageRef& p : dropped) scheduler_.set_held(p.kind, p.id, false);
  }
}

}  // namespace lodstream::cli
