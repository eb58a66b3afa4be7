// PackageWriter: streams nodes' encoded bytes into zstd-compressed data pages of a new .lods file, then
// writes the index pages, the root index and the header, and renames the file into place. Data pages are
// compressed as TBB tasks while the caller goes on (encoding, adding), written in page order as they
// complete; index pages all at once. Until finish() returns, only a
// temporary file next to the target exists (removed by the destructor if finish() was not reached), so an
// interrupted bake never leaves a broken package.
//
// Page packing follows the caller: nodes added between two end_group() calls form a group (a DAG group's
// clusters, a subtree's coarse levels); groups are appended in call order and a page is closed before a group
// that would overflow it, so a group is split only when it alone exceeds the page size. Memory: 34 pages and
// one group of encoded bytes, plus the node records given to finish() and their index pages — never the
// whole geometry.
//
// Typical use (encoding may run in parallel; adding is serial):
//   PackageWriter w("scene.lods");
//   for each group in page order: for each node: w.add_node(id, codec.encode(geometry, grid)); w.end_group();
//   (or, for a record of several clusters, w.add_record(ids, codec.encode(record, grid)))
//   w.finish(scene, records, root_node_count);
#pragma once

#include <tbb/task_group.h>

#include <atomic>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <span>
#include <vector>

#include "package/format.hpp"
#include "package/index.hpp"

namespace lodstream::package {

struct WriterOptions {
  // Target decompressed size of a data page; stored pages come out at roughly 40-90 % of it (DESIGN.md asks
  // for 16-64 KB transfers). 40 KB since format 13, whose nodes hold their traversal symbols already
  // rANS-coded (less to decompress for the same stored bytes): at 48 KB the city's pages went 1,278 -> 1,033
  // and its simulated streams (`bench stream --path gen:fly --link bandwidth=10mbit,rtt=80ms`, seconds to
  // benefit 0.95, sse-pull / push / oracle) 1.133 / 0.700 / 0.633 -> 1.300 / 0.767 / 0.700; at 40 KB 1,306
  // pages and 1.133 / 0.667 / 0.600, elephant_1m 1.000 / 0.800 / 0.733 -> 0.967 / 0.767 / 0.700, motorBike
  // unchanged (0.967 / 0.933 / 0.867). Bytes against 48 KB: elephant_1m +0.5 %, city +0.07 %,
  // refined_elephant -0.4 %.
  size_t page_bytes = 40 * 1024;
  // zstd level of data and index pages: measured on refined_elephant, level 9 is 4x faster to write than 15
  // (8 vs 2 M triangles per second per core); with codec 3 its data pages are 2.6 % larger than at 15
  // (572,635 vs 557,595 B), with codec 1 0.3 %.
  // Data pages also get the minimum match length that suits their codec (writer.cpp, page_min_match).
  int zstd_level = 9;
  // Node records per index page (ids beyond the root index's).
  uint32_t nodes_per_index_page = 1024;
  // The codec id the root index names (the one that encoded the nodes added): node_codec(codec) must exist.
  uint32_t codec = default_node_codec().id();
};

struct WrittenPackage {
  uint64_t bytes = 0;        // file size
  uint64_t page_bytes = 0;   // stored (compressed) bytes of all data pages
  uint64_t index_bytes = 0;  // stored bytes of the index pages
  uint64_t root_index_bytes =
      0;  // stored bytes of the root index (what a first frame needs, with the trailer)
  uint32_t pages = 0, index_pages = 0, nodes = 0;
  ContentHash content_hash;
};

class PackageWriter {
 public:
  // Creates the temporary file; throws lodstream::Error naming it if that fails.
  explicit PackageWriter(std::filesystem::path file, WriterOptions options = {});
  ~PackageWriter();
  PackageWriter(const PackageWriter&) = delete;
  PackageWriter& operator=(const PackageWriter&) = delete;

  // Appends node `id`'s bytes (from the package's codec, or raw bytes for NodeEncoding::raw) to the current
  // group. Each id once.
  void add_node(uint32_t id, std::span<const uint8_t> bytes);
  // Appends a record of several clusters (NodeGeometry::cluster_triangles: the codec's bytes of them all) to
  // the current group: node ids[c] is its cluster c (NodeRecord::cluster), all of them pointing at these
  // bytes. 1..kMaxRecordClusters ids, each id once.
  void add_record(std::span<const uint32_t> ids, std::span<const uint8_t> bytes);
  // Closes the current group (see the packing rule above).
  void end_group();
  // Stores an opaque byte string (an embedded texture file) uncompressed in its own range; returns its blob
  // id.
  uint32_t add_blob(std::span<const uint8_t> bytes);

  // `nodes[i]` is node i; each must have been added (its page, offset and size are filled in here). Node ids
  // [0, root_nodes) go into the root index: number the coarse nodes a first frame needs first. Their
  // (error, sphere) pairs are stored rounded up (round_pairs, pair_rounding.hpp): a reader gets errors and
  // spheres at least as large, with every invariant of inspect --verify kept. The index is validated by the
  // reader's own parser before the file is renamed into place. Throws lodstream::Error.
  WrittenPackage finish(PackageScene scene, std::vector<NodeRecord> nodes, uint32_t root_nodes);

 private:
  void place(size_t first, size_t end);  // moves group entries [first, end) into the current page
  void flush_page();                     // closes the current page: its compression starts as a task
  // Writes the compressed pages at the front of the queue, in page order; waits for every task first when
  // `all` or when more than kPendingPages are queued.
  void write_pending(bool all);
  Range write_stored(std::span<const uint8_t> bytes, uint32_t raw_size);
  void write(std::span<const uint8_t> bytes, bool hashed);

  struct Entry {
    std::vector<uint32_t> ids;  // the record's clusters
    size_t offset, size;        // in group_bytes_
  };
  struct Location {
    uint32_t page = kNone, offset = 0, size = 0, cluster = 0;
    bool added = false;
  };

  std::filesystem::path file_, temp_;
  WriterOptions options_;
  std::FILE* out_ = nullptr;
  uint64_t position_ = 0;
  ContentHasher hasher_;
  std::vector<uint8_t> group_bytes_;
  std::vector<Entry> group_;
  std::vector<uint8_t> page_;
  std::vector<uint32_t> page_nodes_;  // the sizes of page_'s nodes, in order (page_parts.hpp)
  // Closed pages not yet written, in page order, each compressed by a task of compressing_ (zstd was a
  // serial 3 % of an elephant_1m bake; compressed 16 at a time, the pages left a core idle while the caller
  // encoded and added nodes on one), written in page order, so the bytes do not depend on thread timing. A
  // deque: a task's page stays in place while pages are added behind it.
  struct PendingPage {
    std::vector<uint8_t> raw, stored;
    std::vector<uint32_t> node_sizes;
    std::atomic<bool> compressed{false};
  };
  static constexpr size_t kPendingPages = 32;
  std::deque<PendingPage> pending_;
  tbb::task_group compressing_;
  std::vector<Location> locations_;  // by node id
  std::vector<Range> pages_, blobs_;
  uint64_t page_bytes_ = 0;
};

}  // namespace lodstream::package
