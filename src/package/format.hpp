// The fixed parts of the .lods format: header/trailer, limits, checksums, content hash and page compression.
//
// File layout (all integers little-endian):
//   [header 64 B][data pages and blobs][index pages][root index][trailer 64 B]
// The trailer is a byte-for-byte copy of the header, so a client gets the trailer and (usually) the whole
// root index with ONE suffix range request (`bytes=-65536`), or reads the header at offset 0 first. Header
// fields:
//   0  magic "\x89LODS\r\n\x1a"        8  u32 format version          12 u32 header size (64)
//   16 u64 file size                    24 u64 root index offset       32 u32 root index size (zstd)
//   36 u32 root index size raw          40 u64 XXH3-64 of the root index bytes
//   48 16 B content hash: XXH3-128 of every byte between header and trailer (low 64 bits, then high)
// The content hash names a package's content (HTTP ETag, client cache key); it is checked on demand
// (PackageReader::verify) because that reads the whole file. Each page, index page, blob and the root index
// carry their own XXH3-64 of their stored bytes, checked on every read (about 20 GB/s, free next to zstd).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace lodstream::package {

inline constexpr std::array<uint8_t, 8> kMagic = {0x89, 'L', 'O', 'D', 'S', '\r', '\n', 0x1a};
// 2: node records coded against their run (index.hpp); 3: data pages stored by part (page_parts.hpp); 4: a
// node record names its cluster within a record of several clusters (index.hpp, NodeRecord::cluster); 5:
// compact (error, sphere) pairs (index.hpp, pair_rounding.hpp); 6: normals coded in the frame of their
// prediction (predicted_normals.hpp), pages of codecs 2 and 3 store their residuals entropy-coded
// (page_parts.hpp, residual_coder.hpp); 7: 9-bit normals' frame scale 0.49 (predicted_normals.cpp), pages
// store the connectivity's references apart from its symbols and the traversal symbols entropy-coded with
// context (page_parts.hpp, symbol_coder.hpp); 8: traversal symbols' cluster codes stored by recency
// (symbol_coder.hpp); 9: positions predicted on the gate triangle's plane (predictive_node.hpp,
// kPlanePrediction), position residuals coded in two streams (page_parts.hpp, the split form); 10: positions
// predicted by the average of the parallelograms the traversal joins (predictive_node.hpp,
// kMultiParallelogram); 11: closed vertices' normals derived at every DAG level, not level 0 only
// (derived_normals.hpp; the encoder's choice, decoders unchanged); 12: traversal symbols stored as their
// kind's rank in the gate's context of decoded triangles (traversal_connectivity.hpp, ranked symbols); index
// records without vertex counts, a node's own sphere coded against its parents', parents implied by the run's
// children lists, repeated children lists as references, range tables as offset deltas and varints
// (index.hpp); 13: a record's traversal symbols one rANS stream under fixed tables, decoded inside the
// traversal by the gate's context (traversal_connectivity.hpp, traversal_tables.hpp); no connectivity form
// byte in pages (page_parts.hpp); normal residuals may be one paired stream of built-in tables, component 1
// in the context of component 0 (page_parts.hpp's paired form, residual_coder.hpp); spheres that do not fit
// their parents' on their grid rounded on the cell's corners or the next grid (pair_rounding.hpp), a
// representation's grid origin not stored when it is its bounds' minimum (index.cpp, kGridOriginAtBoundsMin);
// 14: coarse clusters' normals at 7 bits, 6 from an error of 16 finest steps (bake's precision, cmd_bake.cpp;
// the encoder's choice, decoders unchanged).
inline constexpr uint32_t kFormatVersion = 14;
inline constexpr size_t kHeaderSize = 64;

// Hard limits a reader enforces before allocating: no valid writer output exceeds them.
inline constexpr uint32_t kMaxRootRawBytes = 64u << 20;
inline constexpr uint32_t kMaxIndexPageRawBytes = 16u << 20;
inline constexpr uint32_t kMaxPageRawBytes = 16u << 20;

struct ContentHash {
  uint64_t low = 0, high = 0;
  bool operator==(const ContentHash&) const = default;
  // 32 lowercase hex digits (high then low), usable as an HTTP ETag or a cache directory name.
  std::string hex() const;
};

struct Header {
  uint32_t version = kFormatVersion;
  uint64_t file_size = 0;
  uint64_t root_offset = 0;
  uint32_t root_size = 0;
  uint32_t root_raw_size = 0;
  uint64_t root_checksum = 0;
  ContentHash content_hash;
};

std::array<uint8_t, kHeaderSize> encode_header(const Header& header);
// Parses and checks magic, version and header size, and that the root index lies between the header and the
// trailer of a file of `file_size` bytes. `context` names the file and which copy (header or trailer).
Header decode_header(std::span<const uint8_t, kHeaderSize> bytes, uint64_t file_size,
                     const std::string& context);

// XXH3-64 of `bytes` (the per-page checksum).
uint64_t checksum64(std::span<const uint8_t> bytes);

// Streaming XXH3-128 (the content hash). Cost: about 20 GB/s.
class ContentHasher {
 public:
  ContentHasher();
  ~ContentHasher();
  ContentHasher(const ContentHasher&) = delete;
  ContentHasher& operator=(const ContentHasher&) = delete;
  void update(std::span<const uint8_t> bytes);
  ContentHash digest() const;

 private:
  void* state_;
};

// zstd frame of `raw` at `level` (1..22), with matches of at least `min_match` bytes (3..7; 0 = the level's
// own). Throws lodstream::Error if zstd fails.
std::vector<uint8_t> zstd_compress(std::span<const uint8_t> raw, int level, int min_match = 0);
// One zstd frame of the concatenation of `parts`, as zstd_compress, but each part ends a zstd block, so that
// each part's literals and sequences get entropy tables of their own (page_parts.hpp).
std::vector<uint8_t> zstd_compress_parts(std::span<const std::span<const uint8_t>> parts, int level,
                                         int min_match = 0);
// Decompresses one zstd frame that must hold exactly `raw_size` bytes (checked against the frame header
// before allocating, and after). `context` names the file and part for the error message.
std::vector<uint8_t> zstd_decompress(std::span<const uint8_t> frame, uint32_t raw_size,
                                     const std::string& context);
// Decompresses one zstd frame that declares at most `max_size` bytes (checked before allocating).
std::vector<uint8_t> zstd_decompress_at_most(std::span<const uint8_t> frame, uint64_t max_size,
                                             const std::string& context);
// The content size that a zstd frame declares; throws unless it declares one of at most `max_size` bytes.
// Cost: O(1) (the frame header).
uint64_t zstd_declared_size(std::span<const uint8_t> frame, uint64_t max_size, const std::string& context);
// Decompresses one zstd frame into `out`, which must be its declared size (zstd_declared_size), with one
// zstd context per thread (created once); throws on a corrupted frame. Lets a caller decompress into a
// buffer it keeps. Cost: the decompression.
void zstd_decompress_to(std::span<const uint8_t> frame, std::span<uint8_t> out, const std::string& context);

}  // namespace lodstream::package
