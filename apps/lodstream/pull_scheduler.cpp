#include "pull_scheduler.hpp"

#include "core/error.hpp"

namespace lodstream::cli {

using schedule::PageKind;

PullScheduler::PullScheduler(package::PackageReader reader, PullFetcher::SourceFactory make_source,
                             PullOptions fetch, PageInbox& frames, PullOrder order, double tau,
                             std::span<const schedule::PageRef> held)
    : reader_(std::move(reader)),
      records_(reader_, no_pages_),
      scheduler_(reader_.root()),
      frames_(frames),
      order_(order),
      tau_(tau),
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

void PullScheduler::wake() {
  {
    std::lock_guard lock(mutex_);
    woken_ = true;
  }
  wake_.notify_all();
}

void PullScheduler::publish(const schedule::ViewSample& latest) {
  {
    std::lock_guard lock(mutex_);
    latest_ = latest;
    ++view_generation_;
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

bool PullScheduler::relay() {
  bool index = false;
  for (ArrivedPage& a : fetched_.take()) {
    if (a.page.kind == PageKind::index) {
      reader_.add_index_page(a.page.id, a.bytes);  // checked here: a bad page is the transport's failure
      index = true;
    }
    frames_.put(std::move(a));
  }
  return index;
}

void PullScheduler::run() {
  const package::RootIndex& root = reader_.root();
  uint64_t planned_generation = 0;
  bool room_left = true;  // the last plan filled the room it had: there may be more to fetch
  for (;;) {
    std::optional<schedule::ViewSample> sample;
    std::vector<uint32_t> evicted;
    uint64_t generation = 0;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || woken_; });
      if (stop_) return;
      woken_ = false;
      sample = latest_;
      generation = view_generation_;
      evicted.swap(evicted_);
    }
    for (uint32_t page : evicted) scheduler_.set_held(PageKind::data, page, false);
    bool index_arrived = false;
    try {
      index_arrived = relay();
    } catch (const Error& e) {
      frames_.fail(e.what());
      return;
    }
    if (std::string error = fetched_.error(); !error.empty()) {
      frames_.fail(error);
      return;
    }
    if (!sample) continue;
    const uint64_t in_flight = fetcher_.in_flight_bytes(), window = fetcher_.window_bytes();
    if (in_flight >= window) continue;
    const bool changed = generation != planned_generation || index_arrived || !evicted.empty();
    if (!changed && !room_left) continue;
    planned_generation = generation;

    const schedule::ScheduleOptions options{tau_, window - in_flight, SIZE_MAX};
    const auto predicted = schedule::predicted_views(*sample, 0.0);
    const std::vector<schedule::PageRef> pages =
        order_ == PullOrder::sse ? scheduler_.next_sse(reader_.scene(), records_, predicted[0].view, options)
                                 : scheduler_.next(reader_.scene(), records_, predicted, options);
    uint64_t bytes = 0;
    for (const schedule::PageRef& p : pages) {
      scheduler_.set_held(p.kind, p.id);
      fetcher_.request(p, p.kind == PageKind::data ? root.pages[p.id] : root.index_pages[p.id].range);
      bytes += p.bytes;
    }
    room_left = !pages.empty() && bytes >= options.max_bytes;
    std::lock_guard lock(mutex_);
    ++plans_;
  }
}

}  // namespace lodstream::cli
