// A byte source that serves a page from the client's disk cache when it holds a valid copy, and from the
// network otherwise (issue 5: a thin client's memory cache evicts pages it may need again; the disk copy
// stored when they first arrived is read back instead of fetching them twice).
//
// The pull transport reads whole pages: each read is one page's stored byte range. A read whose offset and
// size are exactly a page's Range in the root index, and whose page file under the DiskCache has that size
// and that XXH3-64, is answered from the file; anything else (the root index, a page not on disk, a file that
// fails its checks) goes to the inner source unchanged. The pages answered from disk are recorded, so that
// the frame thread installs them as restored, not received, and does not store them again.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <unordered_map>

#include "package/byte_source.hpp"
#include "package/index.hpp"
#include "runtime/disk_cache.hpp"

namespace lodstream::runtime {

// What every DiskFirstSource of one client shares: the disk cache, the pages by offset, and the pages served
// from disk not yet taken by the frame thread. Thread-safe.
class DiskPages {
 public:
  // Pages of `root` (data and index pages) looked up by their offset. Cost: O(pages).
  DiskPages(DiskCache disk, const package::RootIndex& root);

  // Fills `out` from the disk copy of the page stored at [offset, offset + out.size()) and returns true when
  // there is one that passes its size and checksum checks; false otherwise (nothing recorded). Cost: a hash
  // lookup; on a hit one file read and an XXH3-64 of the page.
  bool read(uint64_t offset, std::span<uint8_t> out);

  // True (once) when `page` was served from disk since the last call for it; the frame thread asks for
  // each arrival.
  bool take_served(const schedule::PageRef& page);

 private:
  DiskCache disk_;
  std::unordered_map<uint64_t, std::pair<schedule::PageRef, package::Range>> by_offset_;
  std::mutex mutex_;
  std::set<std::pair<int, uint32_t>> served_;
};

class DiskFirstSource final : public package::ByteSource {
 public:
  DiskFirstSource(std::shared_ptr<const package::ByteSource> inner, std::shared_ptr<DiskPages> pages)
      : inner_(std::move(inner)), pages_(std::move(pages)) {}

  uint64_t size() const override { return inner_->size(); }
  // The disk copy when DiskPages has one, else inner's read (throws as inner does).
  void read(uint64_t offset, std::span<uint8_t> out) const override;
  const std::string& name() const override { return inner_->name(); }

 private:
  std::shared_ptr<const package::ByteSource> inner_;
  std::shared_ptr<DiskPages> pages_;
};

}  // namespace lodstream::runtime
