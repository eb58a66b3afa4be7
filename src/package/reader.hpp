// PackageReader: reads a .lods package through a ByteSource, fetching only what is asked for. Opening costs
// one read (the file's last 64 KiB: trailer and, for any root index that fits, the root index) and validates
// the whole root index; index pages and data pages are fetched on demand. Every offset, size, count and index
// is checked before use and every stored range's checksum before decompression, so a truncated, corrupted or
// hostile file gives a one-line lodstream::Error naming the source and what is wrong, never a crash or an
// allocation beyond the format's limits (format.hpp).
//
// Thread safety: const member functions may run concurrently (read_page, unpack_page, decode); node() and
// decode_node() load index pages into the reader and need external synchronisation.
#pragma once

#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "package/byte_source.hpp"
#include "package/format.hpp"
#include "package/index.hpp"
#include "package/index_page_map.hpp"

namespace lodstream::package {

class PackageReader {
 public:
  explicit PackageReader(std::shared_ptr<const ByteSource> source);
  // A reader over a local file.
  static PackageReader open(const std::filesystem::path& file);

  const ByteSource& source() const { return *source_; }
  const Header& header() const { return header_; }
  const RootIndex& root() const { return root_; }
  const PackageScene& scene() const { return root_.scene; }
  const NodeCodec& codec() const { return *codec_; }
  uint32_t node_count() const { return root_.node_count; }

  // The index page that holds node `id`'s record, or kNone when the root index holds it.
  uint32_t index_page_of(uint32_t id) const;
  // Whether node `id`'s record is available without a read.
  bool has_node(uint32_t id) const;
  // Node `id`'s record when it is available without a read (in the root index or an index page already
  // here), else nullptr (also for an id out of range). Never reads. Cost: one IndexPageMap look-up
  // (has_node followed by node() took two).
  const NodeRecord* held_node(uint32_t id) const;
  // Node `id`'s record, reading its index page first if needed (one read of that page).
  const NodeRecord& node(uint32_t id);
  // Installs index page `page` from bytes received some other way (a push stream): checked like a read.
  void add_index_page(uint32_t page, std::span<const uint8_t> stored);

  // Data page `page`, read (into a per-thread buffer kept at the largest page read), checked and
  // decompressed.
  std::vector<uint8_t> read_page(uint32_t page) const;
  // The same into `buffer` (grown when smaller, never shrunk): returns its first bytes, the page. A buffer
  // kept across pages is allocated and zero-filled once (decompress_page), for a caller done with each page
  // before the next.
  std::span<const uint8_t> read_page(uint32_t page, std::vector<uint8_t>& buffer) const;
  // Checks and decompresses data page `page`'s stored bytes received some other way.
  std::vector<uint8_t> unpack_page(uint32_t page, std::span<const uint8_t> stored) const;
  std::span<const uint8_t> unpack_page(uint32_t page, std::span<const uint8_t> stored,
                                       std::vector<uint8_t>& buffer) const;
  // Node `id`'s bytes inside its decompressed page.
  std::span<const uint8_t> node_bytes(uint32_t id, std::span<const uint8_t> page);
  // Decodes codec node `id` from its decompressed page and checks the result against the node's record
  // (counts, and every index within the representation's vertices). A node that is one cluster of a record
  // (NodeRecord::cluster) gets that cluster alone (records.hpp); the last record decoded is kept (its
  // buffers reused by the next), so decoding its clusters one after another (consecutive ids) decodes it
  // once.
  DecodedNode decode_node(uint32_t id, std::span<const uint8_t> page);
  // The same into `out`, every field of which it overwrites, reusing out's buffers (extract_cluster's):
  // a caller that decodes many nodes into one DecodedNode, or recycles those it drops, allocates once.
  void decode_node(uint32_t id, std::span<const uint8_t> page, DecodedNode& out);
  // read_page + decode_node.
  DecodedNode load_node(uint32_t id);
  // Blob `blob` (an embedded texture file), read and checked.
  std::vector<uint8_t> read_blob(uint32_t blob) const;

  // Reads the whole file: the header at offset 0 must equal the trailer and the content hash must match.
  void verify() const;
  // verify(), then loads every index page, unpacks every data page and decodes every codec node. Cost: a full
  // read and decode of the package.
  void verify_contents();

 private:
  std::vector<uint8_t> read_range(const Range& range, const std::string& what) const;
  // Throws unless `stored` has the range's size and checksum.
  void check_stored(const Range& range, std::span<const uint8_t> stored, const std::string& what) const;
  std::vector<uint8_t> unpack(const Range& range, std::span<const uint8_t> stored,
                              const std::string& what) const;
  void check_layout() const;
  // node_bytes for node `id`, whose record `n` the caller has (one look-up of the record, not two).
  std::span<const uint8_t> record_bytes(uint32_t id, const NodeRecord& n,
                                        std::span<const uint8_t> page) const;
  std::string where(const std::string& what) const { return source_->name() + ": " + what; }

  std::shared_ptr<const ByteSource> source_;
  std::array<uint8_t, kHeaderSize> trailer_{};
  Header header_;
  RootIndex root_;
  IndexPageMap index_map_{RootIndex{}};
  const NodeCodec* codec_ = nullptr;
  std::vector<std::vector<NodeRecord>> index_pages_;  // loaded records, by index page (empty until loaded)
  struct LastRecord {
    bool valid = false;
    uint32_t page = 0, offset = 0, size = 0;
    DecodedNode decoded;
    std::vector<size_t> firsts;  // cluster_firsts(decoded)
  };
  LastRecord last_record_;    // decode_node's last record
  std::string node_context_;  // decode_node's error context ("FILE: node N (page P)"), reused
};

}  // namespace lodstream::package
