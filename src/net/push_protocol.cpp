#include "net/push_protocol.hpp"

#include "schedule/cache_budget.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream {

using schedule::PageKind;
using schedule::PageRef;

PushPackage::PushPackage(std::string name_, std::shared_ptr<const package::PackageReader> reader_)
    : name(std::move(name_)), reader(std::move(reader_)), records(*reader) {}

PushProtocol::PushProtocol(std::shared_ptr<const PushPackage> package, PushProtocolOptions options)
    : package_(std::move(package)),
      options_(options),
      scheduler_(package_->reader->root()),
      released_(package_->reader->root().pages.size(), false),
      on_disk_(package_->reader->root().pages.size(), false),
      remaining_(package_->reader->root().pages.size() + package_->reader->root().index_pages.size()) {}

std::optional<wire::Message> PushProtocol::on_message(const wire::Message& message, double now_s) {
  if (!welcomed_) {
    auto* hello = std::get_if<wire::Hello>(&message);
    if (!hello)
      throw wire::WireError(std::string("wire: expected hello first, got ") + wire::type_name(message));
    if (hello->package != package_->name)
      throw wire::WireError("wire: hello names package '" + hello->package + "' on the stream of '" +
                            package_->name + "'");
    const package::PackageReader& reader = *package_->reader;
    const auto hash = reader.header().content_hash;
    if (hello->cached_hash == hash) {
      auto hold = [&](const std::vector<wire::PageRun>& runs, PageKind kind, size_t count) {
        for (const auto& run : runs)
          for (uint64_t p = run.first; p < uint64_t(run.first) + run.count && p < count; ++p)
            if (!scheduler_.held(kind, uint32_t(p))) mark_sent(scheduler_.page(kind, uint32_t(p)));
      };
      hold(hello->held, PageKind::data, reader.root().pages.size());
      hold(hello->held_index, PageKind::index, reader.root().index_pages.size());
      for (const auto& run : hello->on_disk)
        for (uint64_t p = run.first; p < uint64_t(run.first) + run.count && p < on_disk_.size(); ++p)
          set_on_disk(uint32_t(p), true);
    }
    cache_budget_ = hello->cache_budget_bytes;
    triangle_budget_ = schedule::affordable_triangles(reader.root(), cache_budget_);
    welcomed_ = true;
    return wire::Welcome{hash, reader.source().size(), uint32_t(reader.root().pages.size())};
  }
  if (auto* ack = std::get_if<wire::Ack>(&message)) {
    if (ack->last_sequence > sequence_)
      throw wire::WireError("wire: ack of page " + std::to_string(ack->last_sequence) + ", but only " +
                            std::to_string(sequence_) + " were sent");
    link_.on_ack(ack->last_sequence, now_s);
    if (ack->last_sequence > acked_) {
      acked_ = ack->last_sequence;
      last_progress_s_ = now_s;
    }
    ++counters_.acks;
  } else if (auto* view = std::get_if<wire::ViewUpdate>(&message)) {
    schedule::ViewSample s;
    s.time_s = view->client_time_s;
    s.eye = view->eye;
    s.forward = view->forward;
    s.up = view->up;
    s.velocity = view->velocity;
    s.angular_velocity = view->angular_velocity;
    s.fov_y_radians = view->fov_y_radians;
    s.width = view->viewport_width;
    s.height = view->viewport_height;
    if (std::abs(glm::dot(glm::normalize(s.forward), glm::normalize(s.up))) > 0.9999)
      throw wire::WireError("wire: view message: up is parallel to forward");
    // A converged plan stays so while the client reports the same pose (a still camera: its predictions
    // are the same views).
    if (!view_ || view_->eye != s.eye || view_->forward != s.forward || view_->up != s.up ||
        view_->velocity != s.velocity || view_->angular_velocity != s.angular_velocity ||
        view_->fov_y_radians != s.fov_y_radians || view_->width != s.width || view_->height != s.height)
      plan_converged_ = false;
    view_ = s;
    view_received_s_ = now_s;
    if (!planned_view_s_ || s.time_s < *planned_view_s_ ||
        s.time_s - *planned_view_s_ >= options_.replan_interval_s)
      planned_.clear();  // re-planned from the new prediction at the next send
    ++counters_.views;
  } else if (auto* released = std::get_if<wire::Released>(&message)) {
    const size_t count = package_->reader->root().pages.size();
    for (const wire::PageRun& run : released->pages) {
      if (uint64_t(run.first) + run.count > count)
        throw wire::WireError("wire: released message: pages " + std::to_string(run.first) + ".." +
                              std::to_string(uint64_t(run.first) + run.count - 1) + " but the package has " +
                              std::to_string(count));
      for (uint32_t p = run.first; p < run.first + run.count; ++p) {
        const bool restore_failed = on_disk_[p] && !released->on_disk;
        set_on_disk(p, released->on_disk);
        if (!scheduler_.held(PageKind::data, p) || released_[p]) continue;
        held_bytes_ -= reader().root().pages[p].raw_size;
        released_[p] = true;
        plan_converged_ = false;  // the cut may need it again, and the idle fill has room
        if (restore_failed) {     // what the view needed is not there: due again at once, as bytes
          scheduler_.set_held(PageKind::data, p, false);
          ++remaining_;
        } else {
          backoff_.released(p, now_s);
        }
      }
    }
  } else if (std::holds_alternative<wire::Bye>(message)) {
    ended_ = true;
  } else {
    throw wire::WireError(std::string("wire: unexpected ") + wire::type_name(message) +
                          " message from a client");
  }
  return std::nullopt;
}

uint64_t PushProtocol::window_bytes() const {
  if (!link_.measured()) return std::max(options_.initial_window_bytes, options_.min_window_bytes);
  return uint64_t(std::max(options_.window_bdp * link_.bdp_bytes(), double(options_.min_window_bytes)));
}

void PushProtocol::plan(double now_s, uint64_t bytes) {
  const package::PackageReader& reader = *package_->reader;
  for (uint32_t p : backoff_.due(now_s))  // released pages the views may have again
    if (released_[p] && scheduler_.held(PageKind::data, p)) {
      scheduler_.set_held(PageKind::data, p, false);
      ++remaining_;
    }
  std::vector<PageRef> pages;
  if (view_) {
    // The present is (now - arrival) past the sample; a page sent now arrives half a round trip later.
    const double lead = (now_s - view_received_s_) + 0.5 * link_.rtt_s();
    const auto views = schedule::predicted_views(*view_, lead, options_.horizons);
    pages = scheduler_.next(reader.scene(), package_->records, views,
                            {options_.tau, bytes, SIZE_MAX, triangle_budget_});
    planned_view_s_ = view_->time_s;
  }
  // No fill before the first view: the view follows the hello within a message, and a window filled in file
  // order before it delays the view's pages by a round trip (motorBike, 10 Mbit/s: 80 KB of index pages that
  // the view's cut needs only part of went first).
  if (pages.empty() && options_.fill_when_idle && view_) {
    // The rest in file order, index pages first, while the client's cache has room for the data pages
    // (decompressed, as it holds them; index pages are not in its cache), never a page it released.
    uint64_t room = cache_budget_ > held_bytes_ ? cache_budget_ - held_bytes_ : 0;
    uint64_t planned = 0;
    for (PageKind kind : {PageKind::index, PageKind::data}) {
      const size_t count =
          kind == PageKind::data ? reader.root().pages.size() : reader.root().index_pages.size();
      for (uint32_t id = 0; id < count && planned < bytes; ++id) {
        const PageRef p = scheduler_.page(kind, id);
        const uint64_t cached = kind == PageKind::data ? reader.root().pages[id].raw_size : 0;
        if (scheduler_.held(kind, id) || cached > room || (kind == PageKind::data && released_[id])) continue;
        pages.push_back(p);
        planned += p.bytes;
        room -= cached;
      }
    }
  }
  planned_.assign(pages.begin(), pages.end());
  plan_converged_ = view_ && pages.empty();
  ++counters_.plans;
}

std::optional<PageToSend> PushProtocol::next_page(double now_s) {
  if (!welcomed_ || ended_) return std::nullopt;
  const uint64_t in_flight = link_.bytes_in_flight(), window = window_bytes();
  if (in_flight >= window) return std::nullopt;
  while (!planned_.empty() && scheduler_.held(planned_.front().kind, planned_.front().id))
    planned_.pop_front();
  if ((planned_.empty() && !plan_converged_) || backoff_.due_by(now_s))
    plan(now_s, uint64_t(options_.plan_windows * double(window)));
  if (planned_.empty()) return std::nullopt;
  const PageRef page = scheduler_.page(planned_.front().kind, planned_.front().id);  // priced as of now
  planned_.pop_front();
  if (in_flight == 0) last_progress_s_ = now_s;  // the acknowledgement clock starts with the first page out
  ++sequence_;
  const bool restore = page.kind == PageKind::data && on_disk_[page.id];
  link_.on_send(sequence_, page.bytes, now_s, planned_.empty());  // a restore's cost is its message
  mark_sent(page);
  ++counters_.pages_sent;
  counters_.bytes_sent += restore ? 0 : page.bytes;
  counters_.restores += restore;
  counters_.index_pages_sent += page.kind == PageKind::index;
  return PageToSend{sequence_, page, now_s, restore};
}

void PushProtocol::set_on_disk(uint32_t page, bool on_disk) {
  static const uint32_t restore_bytes = uint32_t(wire::encode(wire::Restore{}).size());
  on_disk_[page] = on_disk;
  scheduler_.set_cost(page, on_disk ? restore_bytes : reader().root().pages[page].size);
}

void PushProtocol::mark_sent(const PageRef& page) {
  scheduler_.set_held(page.kind, page.id);
  if (page.kind == PageKind::data) {
    held_bytes_ += reader().root().pages[page.id].raw_size;
    released_[page.id] = false;
  }
  --remaining_;
}

double PushProtocol::ack_deadline() const {
  return link_.bytes_in_flight() > 0 ? last_progress_s_ + options_.ack_timeout_s
                                     : std::numeric_limits<double>::infinity();
}

void PushProtocol::check_timeout(double now_s) const {
  if (now_s > ack_deadline())
    throw wire::WireError("the client acknowledged nothing for " + std::to_string(options_.ack_timeout_s) +
                          " s");
}

}  // namespace lodstream
