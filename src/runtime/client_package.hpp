// What a streaming client knows of one package (DESIGN.md, Client runtime): the root index (a PackageReader
// opened on it), the index pages and data pages that have arrived (installed here: index pages into the
// reader, data pages decompressed into the PageCache), and the PageScheduler's held set, which counts pages
// requested and not yet arrived too, so that nothing is asked for twice. Each frame selects the cut from
// what has arrived and measures its quality; nothing here waits on the network (the transport delivers
// pages; the frame installs them). Pure computation; one thread (the frame loop's).
#pragma once

#include <cstdint>
#include <span>
#include <unordered_set>
#include <utility>
#include <vector>

#include "package/reader.hpp"
#include "runtime/cache.hpp"
#include "runtime/package_nodes.hpp"
#include "runtime/quality.hpp"
#include "schedule/page_scheduler.hpp"

namespace lodstream::runtime {

struct Frame {
  Cut cut;
  FrameQuality quality;
};

class ClientPackage {
 public:
  // `reader`: the package opened over its source (root index read); `cache_bytes`: the page cache's budget.
  ClientPackage(package::PackageReader reader, uint64_t cache_bytes);

  // Installs an arrived page's stored bytes: an index page's records into the reader, a data page (checked
  // and decompressed) into the cache. Throws lodstream::Error when the bytes do not check out.
  void install(schedule::PageKind kind, uint32_t id, std::span<const uint8_t> stored);
  // Installs a page's stored bytes read from the DiskCache (kept from an earlier session, or read back after
  // an eviction): checked like install, not counted as received (bytes_restored instead).
  void restore(schedule::PageKind kind, uint32_t id, std::span<const uint8_t> stored);
  // A page was requested (held by the scheduler until it arrives or the request is dropped).
  void requested(const schedule::PageRef& page);
  // A requested page will not arrive (its request failed): it may be scheduled again.
  void dropped(const schedule::PageRef& page);

  // The cut for `view` from what has arrived, and its quality; then rates the cache's pages for `view` and
  // `predicted` (eviction order) and forgets evicted pages in the held set. Cost: select_cut + frame_quality
  // + page_usefulness.
  Frame frame(const View& view, std::span<const View> predicted, const schedule::CutOptions& options);

  package::PackageReader& reader() { return reader_; }
  const package::PackageScene& scene() const { return reader_.scene(); }
  const PackageNodes& nodes() const { return nodes_; }
  // The arrived data pages, decompressed (what CutGeometry draws from: pages_from_cache(..., unpacked)).
  PageCache& cache() { return cache_; }
  const schedule::PageScheduler& scheduler() const { return scheduler_; }
  // The stored bytes installed so far (what the transport delivered).
  uint64_t bytes_received() const { return bytes_received_; }
  // The stored bytes restored from the DiskCache (an earlier session's pages, pages read back after
  // eviction).
  uint64_t bytes_restored() const { return bytes_restored_; }
  size_t in_flight() const { return in_flight_.size(); }
  // The data pages the cache evicted since the last call (found in frame(), whether the eviction came from
  // frame()'s rating or from an arrival that overflowed the budget), for a scheduler kept elsewhere (a pull
  // scheduler on its own thread, a push server) to schedule again.
  std::vector<uint32_t> take_evicted() { return std::exchange(evicted_, {}); }
  // Pages held (arrived, not merely requested), by kind, sorted (what a Hello tells a push server).
  std::vector<uint32_t> held(schedule::PageKind kind) const;

 private:
  package::PackageReader reader_;
  PageCache cache_;
  PackageNodes nodes_;
  schedule::PageScheduler scheduler_;
  std::unordered_set<uint64_t> in_flight_;  // kind << 32 | id
  void add(schedule::PageKind kind, uint32_t id, std::span<const uint8_t> stored);

  std::vector<bool> cached_;     // data pages put in the cache and not seen evicted yet
  uint64_t evictions_seen_ = 0;  // cache_.evicted_pages() when cached_ was last checked
  uint64_t bytes_received_ = 0, bytes_restored_ = 0;
  std::vector<uint32_t> evicted_;  // since the last take_evicted()
};

}  // namespace lodstream::runtime
