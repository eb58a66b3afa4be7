#include "package/page_parts.hpp"

#include <array>
#include <cstring>

#include "core/error.hpp"
#include "package/byte_planes.hpp"
#include "package/bytes.hpp"
#include "package/format.hpp"
#include "package/meshopt_codec.hpp"
#include "package/residual_coder.hpp"

namespace lodstream::package {

namespace {

// NodeSizeBreakdown's parts, in its order.
constexpr size_t kParts = 7;
constexpr size_t kPositions = 1, kNormals = 2;

std::array<size_t, kParts> part_sizes(const NodeSizeBreakdown& b) {
  return {b.header, b.positions(), b.normals, b.attributes, b.locked, b.indices - b.tail, b.tail};
}

// The byte planes of a node's positions (components 3) or normals (2): `low` bytes of low planes, `bytes` in
// all (NodeSizeBreakdown); nullopt unless they are whole planes.
struct Planes {
  size_t count = 0;
  uint32_t components = 0, width = 0;
};
std::optional<Planes> planes_of(size_t bytes, size_t low, uint32_t components) {
  if (bytes == 0) return Planes{};
  if (low == 0 || low % components != 0 || bytes % low != 0 || bytes / low > 5) return std::nullopt;
  return Planes{low / components, components, uint32_t(bytes / low)};
}

void put_varint(std::vector<uint8_t>& out, uint64_t v) {
  ByteWriter w;
  w.varint(v);
  out.insert(out.end(), w.bytes.begin(), w.bytes.end());
}

// The residual parts' forms (page_parts.hpp).
constexpr uint8_t kPlanesForm = 0, kCodedForm = 1, kSplitForm = 2, kPairedForm = 3;
// The bits a residual the coded form must save over the zstd'd bytes (page_parts.hpp).
constexpr double kMinSavedBits = 0.2;

// The bytes zstd at `level` / `min_match` stores `planes` in, estimated (page_parts.hpp): for levels above 1
// zstd level 1's size / 1.02, 7 times faster than compressing at level 9 to measure it (elephant_1m's
// parts: 124 against 15-20 MB/s) and as close as what decides: level 1 stores the parts of the pages of
// city, elephant_1m, motorBike and refined_elephant 1.2-4.0 % (median per scene) larger than level 9.
double estimated_zstd_size(std::span<const uint8_t> planes, int level, int min_match) {
  if (level <= 1) return double(zstd_compress(planes, level, min_match).size());
  return double(zstd_compress(planes, 1, min_match).size()) / 1.02;
}

// The regrouped bytes (page_parts.hpp), as the size varints and the seven streams, each residual part in the
// smaller form (as zstd at `level` / `min_match` stores it, the planes' size estimated); nullopt when a
// node's bytes do not parse as the codec's (or, for a byte-plane codec, hold no whole planes).
std::optional<std::array<std::vector<uint8_t>, kParts + 1>> regroup(std::span<const uint8_t> page,
                                                                    std::span<const uint32_t> node_sizes,
                                                                    const NodeCodec& codec, int level,
                                                                    int min_match) {
  std::array<std::vector<uint8_t>, kParts + 1> out;  // [0]: the stream sizes, [1 + p]: stream p
  const bool coded = residuals_coded(codec);
  std::vector<uint64_t> residuals[kParts];  // of kPositions and kNormals, coded
  std::vector<uint64_t> split[2];           // the positions' component 0, and components 1 and 2
  std::vector<uint32_t> normal_counts;      // each node's normal residuals per component
  std::vector<int64_t> signed_residuals;
  // The nodes' layouts first, so that the residual arrays are allocated once at their size (grown value by
  // value, each doubling copied them: more than the values themselves).
  std::vector<NodeSizeBreakdown> layouts;
  layouts.reserve(node_sizes.size());
  size_t at = 0, position_values = 0, normal_values = 0;  // a residual per low byte
  for (uint32_t size : node_sizes) {
    try {
      layouts.push_back(codec.breakdown(page.subspan(at, size), "page node"));
    } catch (const Error&) {
      return std::nullopt;  // not a codec node (NodeEncoding::raw)
    }
    position_values += layouts.back().position_low, normal_values += layouts.back().normal_low;
    at += size;
  }
  if (coded) {
    residuals[kPositions].reserve(position_values), residuals[kNormals].reserve(normal_values);
    split[0].reserve(position_values / 3), split[1].reserve(position_values - position_values / 3);
  }
  at = 0;
  for (size_t k = 0; k < node_sizes.size(); ++k) {
    const uint32_t size = node_sizes[k];
    const std::span<const uint8_t> node = page.subspan(at, size);
    const NodeSizeBreakdown& b = layouts[k];
    put_varint(out[1], size);
    const std::array<size_t, kParts> n = part_sizes(b);
    const std::optional<Planes> shape[kParts] = {
        {}, planes_of(n[kPositions], b.position_low, 3), planes_of(n[kNormals], b.normal_low, 2)};
    size_t from = 0;
    for (size_t p = 0; p < kParts; ++p) {
      if (coded && (p == kPositions || p == kNormals)) {
        if (!shape[p]) return std::nullopt;
        const Planes& s = *shape[p];
        signed_residuals.resize(s.count * s.components);
        if (s.count) read_planes(node.data() + from, s.count, s.components, s.width, signed_residuals.data());
        // Appended by size and index (one resize each, not a push_back per value); the values are
        // component-major, so the split form's component 0 is the first s.count.
        std::vector<uint64_t>& all = residuals[p];
        const size_t at = all.size();
        all.resize(at + signed_residuals.size());
        for (size_t i = 0; i < signed_residuals.size(); ++i) all[at + i] = zigzag(signed_residuals[i]);
        if (p == kNormals) normal_counts.push_back(uint32_t(s.count));
        if (p == kPositions) {
          split[0].insert(split[0].end(), all.begin() + at, all.begin() + at + s.count);
          split[1].insert(split[1].end(), all.begin() + at + s.count, all.end());
        }
      }
      out[1 + p].insert(out[1 + p].end(), node.begin() + from, node.begin() + from + n[p]);
      from += n[p];
    }
    at += size;
  }
  if (coded)
    for (size_t p : {kPositions, kNormals}) {
      if (out[1 + p].empty()) continue;
      std::vector<uint8_t> form = {kCodedForm};
      const std::vector<uint8_t> stream = encode_residuals(residuals[p]);
      form.insert(form.end(), stream.begin(), stream.end());
      if (p == kPositions) {  // the split form when smaller (page_parts.hpp)
        const std::vector<uint8_t> first = encode_residuals(split[0]), rest = encode_residuals(split[1]);
        std::vector<uint8_t> split_form = {kSplitForm};
        put_varint(split_form, first.size());
        split_form.insert(split_form.end(), first.begin(), first.end());
        split_form.insert(split_form.end(), rest.begin(), rest.end());
        if (split_form.size() < form.size()) form = std::move(split_form);
      } else {  // the paired form when smaller (page_parts.hpp)
        const std::vector<uint8_t> paired = encode_paired_residuals(residuals[p], normal_counts);
        if (1 + paired.size() < form.size()) {
          form.assign(1, kPairedForm);
          form.insert(form.end(), paired.begin(), paired.end());
        }
      }
      // Coded only when it saves kMinSavedBits a residual (page_parts.hpp): not where zstd finds repeats,
      // nor where it saves too little to pay for its decode.
      const double saved_bits = 8 * (estimated_zstd_size(out[1 + p], level, min_match) - double(form.size()));
      if (saved_bits < kMinSavedBits * double(residuals[p].size())) {
        form.assign(1, kPlanesForm);
        form.insert(form.end(), out[1 + p].begin(), out[1 + p].end());
      }
      out[1 + p] = std::move(form);
    }
  for (size_t p = 0; p < kParts; ++p) put_varint(out[0], out[1 + p].size());
  return out;
}

}  // namespace

bool residuals_coded(const NodeCodec& codec) {
  return codec.id() != MeshoptCodec::kId;
}

std::vector<uint8_t> compress_page(std::span<const uint8_t> page, std::span<const uint32_t> node_sizes,
                                   const NodeCodec& codec, int level, int min_match) {
  const auto streams = regroup(page, node_sizes, codec, level, min_match);
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
  std::vector<uint8_t> page;
  decompress_page(stored, raw_size, codec, where, page);
  return page;
}

std::span<const uint8_t> decompress_page(std::span<const uint8_t> stored, uint32_t raw_size,
                                         const NodeCodec& codec, const std::string& where,
                                         std::vector<uint8_t>& buffer) {
  const uint64_t declared = zstd_declared_size(stored, 2 * uint64_t(raw_size) + 64, where);
  if (buffer.size() < raw_size) buffer.resize(raw_size);
  const std::span<uint8_t> page(buffer.data(), raw_size);  // every byte written below (or an error thrown)
  if (declared == raw_size) {                              // stored whole
    zstd_decompress_to(stored, page, where);
    return page;
  }
  // The regrouped bytes, in a buffer kept across pages: allocated (and cleared) once, not per page.
  thread_local std::vector<uint8_t> regrouped;
  if (regrouped.size() < declared) regrouped.resize(declared);
  const std::span<const uint8_t> content(regrouped.data(), declared);
  zstd_decompress_to(stored, std::span(regrouped).first(declared), where);
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

  std::array<bool, kParts> coded{};     // the residual parts in a coded form
  bool split = false;                   // the positions in the split form: stream[kPositions] its component 0
  bool paired = false;                  // the normals in the paired form
  std::span<const uint8_t> split_rest;  // and its other components
  if (residuals_coded(codec))
    for (size_t p : {kPositions, kNormals}) {
      if (stream[p].empty()) continue;
      const uint8_t form = stream[p][0];
      if (form != kPlanesForm && form != kCodedForm && !(form == kSplitForm && p == kPositions) &&
          !(form == kPairedForm && p == kNormals))
        r.fail("invalid residual part form");
      paired = paired || form == kPairedForm;
      coded[p] = form != kPlanesForm, stream[p] = stream[p].subspan(1);
      if (form == kSplitForm) {
        ByteReader s(stream[p], where);
        const uint64_t first = s.varint();
        if (first > s.remaining()) s.fail("split residual streams larger than their part");
        split = true, stream[p] = s.bytes(first, "residual stream"), split_rest = s.bytes(s.remaining(), "");
      }
    }
  ResidualDecoder positions(coded[kPositions] ? stream[kPositions] : std::span<const uint8_t>(), where),
      position_rest(split_rest, where),
      normals(coded[kNormals] ? stream[kNormals] : std::span<const uint8_t>(), where, paired);
  std::array<size_t, kParts> used{};  // bytes of each stream consumed
  ByteReader headers(stream[0], where);
  size_t at = 0;
  while (!headers.at_end()) {
    const uint64_t node_size = headers.varint();
    if (node_size == 0 || node_size > raw_size - at) headers.fail("node size past the page's end");
    used[0] = headers.position();
    const NodeSizeBreakdown b = codec.layout(stream[0].subspan(used[0]), node_size, where);
    const std::array<size_t, kParts> n = part_sizes(b);
    for (size_t p = 0; p < kParts; ++p) {
      if (coded[p]) {
        const std::optional<Planes> s =
            p == kPositions ? planes_of(n[p], b.position_low, 3) : planes_of(n[p], b.normal_low, 2);
        if (!s) headers.fail("node residuals not in byte planes");
        if (p == kPositions && split) {
          positions.planes(s->count, s->components, s->width, page.data() + at, 0, 1);
          position_rest.planes(s->count, s->components, s->width, page.data() + at, 1, s->components - 1);
        } else {
          (p == kPositions ? positions : normals).planes(s->count, s->components, s->width, page.data() + at);
        }
      } else {
        if (n[p] > stream[p].size() - used[p]) headers.fail("node part past its stream's end");
        std::memcpy(page.data() + at, stream[p].data() + used[p], n[p]);
        used[p] += n[p];
      }
      at += n[p];
    }
    headers.bytes(n[0], "node header");
  }
  positions.finish(), position_rest.finish(), normals.finish();
  for (size_t p = 0; p < kParts; ++p)
    if (used[p] != stream[p].size() && !coded[p]) r.fail("page part streams hold bytes of no node");
  if (at != raw_size) r.fail("page part streams hold fewer bytes than the page");
  return page;
}

}  // namespace lodstream::package
