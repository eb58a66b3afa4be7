#include "view_client.hpp"

#include <algorithm>
#include <cstdio>

#include "core/error.hpp"
#include "full_fetch.hpp"
#include "net/http_source.hpp"
#include "net/push_client.hpp"
#include "net/url.hpp"
#include "pull_scheduler.hpp"
#include "schedule/cache_budget.hpp"
#include "view_motion.hpp"

namespace lodstream::cli {

namespace {

bool starts_with(const std::string& s, const char* prefix) {
  return s.rfind(prefix, 0) == 0;
}

// The package file's URL: the source itself when pulled; for a push stream ws://HOST:PORT/NAME, the same
// server's http://HOST:PORT/NAME.lods (DESIGN.md's addresses).
std::string file_url(const std::string& source) {
  if (!starts_with(source, "ws://")) return source;
  const UrlParts u = split_url(source, "ws://");
  return "http://" + u.host + ":" + u.port + u.target + ".lods";
}

std::shared_ptr<const package::ByteSource> open_source(const std::string& source, bool remote) {
  if (remote) return std::make_shared<HttpSource>(file_url(source));
  return std::make_shared<package::FileSource>(source);
}

uint64_t cache_bytes(const ViewClientOptions& o) {
  return uint64_t(o.cache_mb * 1024 * 1024);
}

// The push hello's fields that do not depend on the package (no hash, nothing held).
wire::Hello push_hello(const std::string& source, const ViewClientOptions& options) {
  wire::Hello hello;
  hello.package = split_url(source, "ws://").target.substr(1);
  hello.cache_budget_bytes = cache_bytes(options);
  hello.triangles_per_frame =
      uint32_t(std::min<uint64_t>(options.budget ? options.budget : UINT32_MAX, UINT32_MAX));
  hello.viewport_width = uint16_t(options.width);
  hello.viewport_height = uint16_t(options.height);
  return hello;
}

// The push session, opened before the root index is read (null unless pushed). Without a disk cache its
// Hello goes out at once; with one, the Hello waits for the root index (it lists the pages on disk) while the
// connection and the WebSocket handshake go ahead.
std::unique_ptr<PushClient> early_push(const std::string& source, const ViewClientOptions& options,
                                       PageInbox& inbox) {
  if (!starts_with(source, "ws://")) return nullptr;
  if (!options.cache_dir.empty()) return std::make_unique<PushClient>(source, inbox);
  return std::make_unique<PushClient>(source, push_hello(source, options), inbox);
}

}  // namespace

ViewClient::ViewClient(const std::string& source, const ViewClientOptions& options)
    : mode_(starts_with(source, "ws://")     ? Mode::push
            : starts_with(source, "http://") ? Mode::pull
                                             : Mode::file),
      package_dir_(mode_ == Mode::file ? std::filesystem::path(source).parent_path()
                                       : std::filesystem::path()),
      pusher_(early_push(source, options, arrived_)),
      client_(package::PackageReader(open_source(source, mode_ != Mode::file)), cache_bytes(options)) {
  cut_options_.tau = options.pixel_error;
  cut_options_.triangle_budget =
      std::min<uint64_t>(options.budget ? options.budget : UINT64_MAX,
                         schedule::affordable_triangles(client_.reader().root(), cache_bytes(options)));
  std::vector<uint32_t> left_on_disk;  // data pages the memory budget left on disk
  if (!options.cache_dir.empty()) {
    disk_.emplace(options.cache_dir, client_.reader().header().content_hash);
    runtime::RestoredPages restored = disk_->restore(client_, cache_bytes(options));
    for (const std::string& w : restored.warnings)
      std::fprintf(stderr, "lodstream: warning: %s\n", w.c_str());
    left_on_disk = std::move(restored.on_disk);
  }

  if (mode_ == Mode::push) {
    if (!disk_) return;
    wire::Hello hello = push_hello(source, options);
    hello.cached_hash = client_.reader().header().content_hash;
    hello.held = wire::page_runs(client_.held(schedule::PageKind::data));
    hello.held_index = wire::page_runs(client_.held(schedule::PageKind::index));
    hello.on_disk = wire::page_runs(left_on_disk);
    pusher_->say_hello(std::move(hello));
    return;
  }
  PullFetcher::SourceFactory make_source;
  PullOptions fetch;
  if (mode_ == Mode::pull) {
    make_source = [url = source] { return std::make_shared<HttpSource>(url); };
  } else {
    make_source = [file = source] { return std::make_shared<package::FileSource>(file); };
    fetch.connections = 1;
    fetch.min_window_bytes = 8u << 20;
  }
  if (disk_) {  // a page evicted from memory and needed again is read back from disk, not fetched twice
    disk_pages_ = std::make_shared<runtime::DiskPages>(*disk_, client_.reader().root());
    make_source = [inner = std::move(make_source), pages = disk_pages_] {
      return std::make_shared<runtime::DiskFirstSource>(inner(), pages);
    };
  }
  if (options.order == "full" || options.window > 0) {
    if (options.window > 0) fetch.connections = options.window;
    baseline_ = std::make_unique<PullFetcher>(std::move(make_source), arrived_, fetch);
    if (options.order == "full") full_ = std::make_unique<FullFetch>();
    window_ = options.window;
    sse_ = options.order == "sse";
    tau_ = options.pixel_error;
    return;
  }
  std::vector<schedule::PageRef> held;
  for (schedule::PageKind kind : {schedule::PageKind::data, schedule::PageKind::index})
    for (uint32_t id : client_.held(kind)) held.push_back({kind, id});
  puller_ = std::make_unique<PullScheduler>(client_.reader(), std::move(make_source), fetch, arrived_,
                                            options.order == "sse" ? PullOrder::sse : PullOrder::benefit,
                                            cut_options_, held);
}

ViewClient::~ViewClient() = default;

const char* ViewClient::mode() const {
  return mode_ == Mode::push ? "push" : mode_ == Mode::pull ? "pull" : "file";
}

uint64_t ViewClient::reconnects() const {
  return puller_ ? puller_->reconnects() : baseline_ ? baseline_->reconnects() : pusher_->reconnects();
}

uint64_t ViewClient::plans() const {
  return puller_ ? puller_->plans() : 0;
}

void ViewClient::request_baseline(std::span<const schedule::WeightedView> predicted) {
  if (full_) {
    full_->request(client_, *baseline_);
    return;
  }
  const package::RootIndex& root = client_.reader().root();
  const uint64_t in_flight = baseline_->in_flight_bytes(), window = baseline_->window_bytes();
  const size_t requests = client_.in_flight(), max_requests = size_t(window_);
  if (window_ ? requests >= max_requests : in_flight >= window) return;
  const schedule::ScheduleOptions s =
      window_
          ? schedule::ScheduleOptions{tau_, UINT64_MAX, max_requests - requests, cut_options_.triangle_budget}
          : schedule::ScheduleOptions{tau_, window - in_flight, SIZE_MAX, cut_options_.triangle_budget};
  const auto pages =
      sse_ ? client_.scheduler().next_sse(client_.scene(), client_.nodes(), predicted[0].view, s)
           : client_.scheduler().next(client_.scene(), client_.nodes(), predicted, s);
  for (const schedule::PageRef& p : pages) {
    client_.requested(p);
    baseline_->request(p,
                       p.kind == schedule::PageKind::data ? root.pages[p.id] : root.index_pages[p.id].range);
  }
}

runtime::Frame ViewClient::frame(const schedule::ViewSample& now) {
  if (std::string error = arrived_.error(); !error.empty()) throw Error(error);
  for (ArrivedPage& a : arrived_.take()) {
    if (a.from_disk) {  // the push server's Restore of a page the disk cache keeps
      const std::string why = disk_ ? disk_->restore_page(client_, a.page.id) : "no --cache-dir";
      if (!why.empty()) {
        std::fprintf(stderr, "lodstream: warning: a restore asked of the disk cache failed: %s\n",
                     why.c_str());
        const uint32_t lost = a.page.id;
        pusher_->released({&lost, 1}, false);  // the server sends its bytes instead
      }
      continue;
    }
    if (disk_pages_ && disk_pages_->take_served(a.page)) {
      client_.restore(a.page.kind, a.page.id, a.bytes);  // read back from disk: already stored there
      continue;
    }
    client_.install(a.page.kind, a.page.id, a.bytes);
    if (disk_) disk_->store(a.page.kind, a.page.id, a.bytes);
  }
  const auto predicted = schedule::predicted_views(now, 0.0);
  if (puller_)
    puller_->publish(now);
  else if (pusher_)
    pusher_->send_view(view_update(now));
  else
    request_baseline(predicted);
  if (full_) return full_->frame(client_, predicted[0].view, tau_);
  std::vector<schedule::View> ahead;
  for (size_t k = 1; k < predicted.size(); ++k) ahead.push_back(predicted[k].view);
  runtime::Frame f = client_.frame(predicted[0].view, ahead, cut_options_);
  const std::vector<uint32_t> evicted = client_.take_evicted();
  if (puller_) puller_->evicted(evicted);
  if (pusher_) pusher_->released(evicted, disk_.has_value());  // every page that arrived is on disk
  return f;
}

}  // namespace lodstream::cli
