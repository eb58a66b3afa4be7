// The streaming client of `lodstream view` (DESIGN.md, Client runtime; the command line's addresses), apart
// from its window or camera path: a source (FILE.lods read locally, http://HOST:PORT/…/NAME.lods pulled from
// lodstream serve or any static server, ws://HOST:PORT/NAME pushed to by lodstream serve), its root index,
// the transport, and per frame the installation of what arrived and the cut for the current view.
//
// Threads: construct, call and destroy a ViewClient on one thread (the frame thread); it owns the
// ClientPackage (package() is for that thread only). The transport runs on threads of its own: a pull or a
// local file has a PullScheduler (its scheduler thread plus the fetcher's readers), a push a PushClient;
// the benchmark's baselines (order `full`, or a window counted in requests) keep the way such clients work:
// they schedule on the frame thread, over a PullFetcher of their own;
// they hand pages over through a PageInbox and take view samples through their own locked slot, so a frame
// never waits on the network or on scheduling.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "net/page_inbox.hpp"
#include "net/pull_fetcher.hpp"
#include "runtime/client_package.hpp"
#include "runtime/disk_cache.hpp"
#include "runtime/disk_first_source.hpp"
#include "schedule/cut.hpp"
#include "schedule/motion.hpp"

namespace lodstream {
class PushClient;
}

namespace lodstream::cli {

class PullScheduler;
class FullFetch;

// Checked by the caller (cmd_view.cpp's option checks): positive finite pixel_error and cache_mb, a known
// order.
struct ViewClientOptions {
  double pixel_error = 1.0;       // tau, pixels
  double cache_mb = 1024.0;       // page cache budget
  uint64_t budget = 0;            // triangles drawn per frame at most (0: no limit)
  std::string order = "benefit";  // pull order: benefit, sse or full (DESIGN.md's `full` policy)
  // Pull: at most this many requests outstanding, over as many connections (0: a window of bytes from the
  // measured bandwidth-delay product). The baselines of bench stream --real (sse-pull: 20, sse-pull-3: 3).
  int window = 0;
  int width = 1280, height = 720;  // the viewport a push server is told in the hello
  // Pages received are kept under DIR/<package content hash>/ (runtime::DiskCache) and restored from it at
  // start (as many as the memory cache holds): never fetched again, and listed in the push hello. A pulled
  // page that is on disk is read from there (runtime::DiskFirstSource), also after the memory cache evicted
  // it. Empty: the cache lives in memory only.
  std::filesystem::path cache_dir;
};

class ViewClient {
 public:
  // Opens `source`: reads the root index (one read, blocking: a local read or one HTTP request), restores
  // the pages kept on disk (options.cache_dir; files that fail their checks are dropped with a warning on
  // standard error) and starts the transport (a push stream without a cache directory starts it first, so
  // that its handshake overlaps the root index's read). Throws lodstream::Error (unreachable server, not a
  // package, a cache directory that cannot be created) naming what failed.
  ViewClient(const std::string& source, const ViewClientOptions& options);
  ~ViewClient();  // stops the transport
  ViewClient(const ViewClient&) = delete;
  ViewClient& operator=(const ViewClient&) = delete;

  // "file", "pull" or "push".
  const char* mode() const;

  // One frame for the view sample `now` (pose and motion): installs the pages that arrived since the last
  // frame (data pages checked and decompressed), hands `now` to the transport (the pull scheduler's slot or a
  // view update to the push server), selects the cut for `now` from what has arrived and measures it; the
  // views predicted from `now` set the cache's eviction order. Throws lodstream::Error when the transport
  // failed. Cost: the pages' decompression + ClientPackage::frame.
  runtime::Frame frame(const schedule::ViewSample& now);

  // The pull scheduler's plans so far (PullScheduler::plans; 0 for a push stream).
  uint64_t plans() const;

  runtime::ClientPackage& package() { return client_; }
  // Times the transport reconnected after losing its server (push: a new session with the held pages in its
  // hello; pull: a new connection for a failed read).
  uint64_t reconnects() const;
  // The local package's folder (textures resolve against it), empty for a remote source.
  const std::filesystem::path& package_dir() const { return package_dir_; }

 private:
  enum class Mode { file, pull, push };
  // The baselines' requests for this frame: what is due (order full), or the scheduler's next pages while
  // the window (requests or bytes) has room. Frame thread.
  void request_baseline(std::span<const schedule::WeightedView> predicted);
  Mode mode_;
  schedule::CutOptions cut_options_;
  std::filesystem::path package_dir_;
  PageInbox arrived_;  // what the transport delivered, for the next frame
  // Push: the WebSocket session, opened before the root index is read so that its connection and handshake
  // overlap that read (as bench stream's simulation has it). Without a cache directory its hello goes out at
  // once (no package hash, nothing held); with one, the hello follows the root read and lists the disk's
  // pages.
  std::unique_ptr<PushClient> pusher_;
  runtime::ClientPackage client_;
  std::optional<runtime::DiskCache> disk_;
  // Pulled with a disk cache: which arrivals were read back from disk (the fetcher's sources are
  // DiskFirstSources over it); null otherwise.
  std::shared_ptr<runtime::DiskPages> disk_pages_;
  std::unique_ptr<PullScheduler> puller_;
  // The baselines: a fetcher scheduled from the frame thread; `full_` for order full.
  std::unique_ptr<PullFetcher> baseline_;
  std::unique_ptr<FullFetch> full_;
  int window_ = 0;
  bool sse_ = false;
  double tau_ = 1.0;
};

}  // namespace lodstream::cli
