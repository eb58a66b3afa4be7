// The client's page cache on disk (issue 5: the cache outlives the connection and the process): the stored
// bytes of every page a client received, kept under DIR/<package content hash>/ as one file per page, named
// `d<id>` (data page) or `i<id>` (index page). A file is written to a temporary name in the same directory
// and renamed, so a reader sees a whole page or none. Because the directory is named by the content hash, a
// changed package (another hash) never finds stale pages.
//
// Nothing read back is trusted: restore() checks each file's size against the page's Range in the root
// index before reading it, then installs it through ClientPackage::restore, which checks the XXH3-64 checksum
// of the Range and decompresses it; a file that fails is deleted and reported, never a crash. Names that are
// not page files are reported and left alone. Pure file I/O (no sockets, no clock); one thread.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "runtime/client_package.hpp"

namespace lodstream::runtime {

struct RestoredPages {
  uint64_t pages = 0;                 // pages installed from disk
  uint64_t stored_bytes = 0;          // their stored (compressed) bytes
  std::vector<std::string> warnings;  // one line per file dropped or ignored, naming it and why
  std::vector<uint32_t> on_disk;      // data pages left on disk (the budget was spent), ascending
};

class DiskCache {
 public:
  // The cache of the package with content hash `hash` under `root` (DIR/<hash hex>/, created if missing).
  // Throws lodstream::Error naming the directory when it cannot be created.
  DiskCache(const std::filesystem::path& root, const package::ContentHash& hash);

  const std::filesystem::path& directory() const { return directory_; }

  // Writes one received page's stored bytes (temporary file, then rename; an existing file is replaced).
  // Throws lodstream::Error naming the file when the write fails. Cost: one file write of `stored`.
  void store(schedule::PageKind kind, uint32_t id, std::span<const uint8_t> stored);

  // Installs into `client` the pages held on disk: every valid index page, then data pages in page order
  // while their decompressed size fits in `budget_bytes` (the memory cache's budget) beside what `client`'s
  // cache already holds. Invalid files (wrong size, checksum or contents, an id the package does not have)
  // are deleted and reported. Cost: one read, checksum and decompression per page loaded.
  RestoredPages restore(ClientPackage& client, uint64_t budget_bytes) const;

  // Installs data page `id` from its file into `client` (a push server's Restore, or a page read back after
  // an eviction). Returns "" on success; otherwise why not (no such page or file, wrong size, checksum or
  // contents), after deleting a file that failed. Cost: one read, checksum and decompression.
  std::string restore_page(ClientPackage& client, uint32_t id) const;

  // Reads page (kind, id)'s file into `out` when it exists and holds exactly out.size() bytes; false
  // otherwise. Checks nothing else (the caller checks the checksum). Safe to call from several threads.
  // Cost: one file read.
  bool read_page(schedule::PageKind kind, uint32_t id, std::span<uint8_t> out) const;

  // The file that holds a page (whether or not it exists).
  std::filesystem::path file(schedule::PageKind kind, uint32_t id) const;

 private:
  // Reads page (kind, id) of `size` stored bytes and installs it into `client`: "" or why it failed.
  std::string load(ClientPackage& client, schedule::PageKind kind, uint32_t id, uint64_t size) const;

  std::filesystem::path directory_;
};

}  // namespace lodstream::runtime
