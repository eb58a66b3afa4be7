#include "package/page_parts.hpp"

#include <array>
#include <cstring>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/format.hpp"
#include "package/meshopt_codec.hpp"

namespace lodstream::package {

namespace {

// NodeSizeBreakdown's parts, in its order, the positions and normals cut into low and high byte planes.
constexpr size_t kParts = 8;

std::array<size_t, kParts> part_sizes(const NodeSizeBreakdown& b) {
  return {b.header,
          b.position_low,
          b.positions() - b.position_low,
          b.normal_low,
          b.normals - b.normal_low,
          b.attributes,
          b.locked,
          b.indices};
}

void put_varint(std::vector<uint8_t>& out, uint64_t v) {
  ByteWriter w;
  w.varint(v);
  out.insert(out.end(), w.bytes.begin(), w.bytes.end());
}

// The regrouped bytes (page_parts.hpp), as the size varints and the eight streams; nullopt when a node's
// bytes do not parse as the codec's.
std::optional<std::array<std::vector<uint8_t>, kParts + 1>> regroup(std::span<const uint8_t> page,
                                                                    std::span<const uint32_t> node_sizes,
                                                                    const NodeCodec& codec) {
  std::array<std::vector<uint8_t>, kParts + 1> out;  // [0]: the stream sizes, [1 + p]: stream p
  size_t at = 0;
  for (uint32_t size : node_sizes) {
    const std::span<const uint8_t> node = page.subspan(at, size);
    NodeSizeBreakdown b;
    try {
      b = codec.breakdown(node, "page node");
    } catch (const Error&) {
      return std::nullopt;  // not a codec node (NodeEncoding::raw)
    }
    put_varint(out[1], size);
    const std::array<size_t, kParts> n = part_sizes(b);
    size_t from = 0;
    for (size_t p = 0; p < kParts; ++p) {
      out[1 + p].insert(out[1 + p].end(), node.begin() + from, node.begin() + from + n[p]);
      from += n[p];
    }
    at += size;
  }
  for (size_t p = 0; p < kParts; ++p) put_varint(out[0], out[1 + p].size());
  return out;
}

}  // namespace

std::vector<uint8_t> compress_page(std::span<const uint8_t> page, std::span<const uint32_t> node_sizes,
                                   const NodeCodec& codec, int level, int min_match) {
  const auto streams = regroup(page, node_sizes, codec);
  if (!streams) return zstd_compress(page, level, min_match);
  std::array<std::span<const uint8_t>, kParts + 1> parts;
  for (size_t i = 0; i <= kParts; ++i) parts[i] = (*streams)[i];
  // The sizes and the header stream share the first block.
  std::vector<uint8_t> head = (*streams)[0];
  head.insert(head.end(), (*streams)[1].begin(), (*streams)[1].end());
  parts[1] = head;
  std::vector<uint8_t> by_part = zstd_compress_parts(std::span(parts).subspan(1), level, min_match);
  if (codec.id() != MeshoptCodec::kId) return by_part;
  std::vector<uint8_t> whole = zstd_compress(page, level, min_match);
  return by_part.size() < whole.size() ? by_part : whole;
}

std::vector<uint8_t> decompress_page(std::span<const uint8_t> stored, uint32_t raw_size,
                                     const NodeCodec& codec, const std::string& where) {
  std::vector<uint8_t> content = zstd_decompress_at_most(stored, 2 * uint64_t(raw_size) + 64, where);
  if (content.size() == raw_size) return content;  // stored whole
  ByteReader r(content, where);
  std::array<std::span<const uint8_t>, kParts> stream;
  std::array<uint64_t, kParts> size;
  for (uint64_t& s : size) s = r.varint();
  uint64_t total = 0;
  for (uint64_t s : size) {
    if (s > r.remaining() - total) r.fail("page part streams larger than the page");
    total += s;
  }
  if (total != r.remaining()) r.fail("page part streams do not add up to the page");
  for (size_t p = 0; p < kParts; ++p) stream[p] = r.bytes(size[p], "page part stream");

  std::vector<uint8_t> page(raw_size);
  std::array<size_t, kParts> used{};  // bytes of each stream consumed
  ByteReader headers(stream[0], where);
  size_t at = 0;
  while (!headers.at_end()) {
    const uint64_t node_size = headers.varint();
    if (node_size == 0 || node_size > raw_size - at) headers.fail("node size past the page's end");
    used[0] = headers.position();
    const std::array<size_t, kParts> n =
        part_sizes(codec.layout(stream[0].subspan(used[0]), node_size, where));
    for (size_t p = 0; p < kParts; ++p) {
      if (n[p] > stream[p].size() - used[p]) headers.fail("node part past its stream's end");
      std::memcpy(page.data() + at, stream[p].data() + used[p], n[p]);
      at += n[p], used[p] += n[p];
    }
    headers.bytes(n[0], "node header");
  }
  for (size_t p = 0; p < kParts; ++p)
    if (used[p] != stream[p].size()) r.fail("page part streams hold bytes of no node");
  if (at != raw_size) r.fail("page part streams hold fewer bytes than the page");
  return page;
}

}  // namespace lodstream::package
