#include "package/predictive_codec.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cstring>
#include <iterator>

#include "core/error.hpp"
#include "package/byte_planes.hpp"
#include "package/bytes.hpp"
#include "package/coarse_positions.hpp"
#include "package/node_header.hpp"
#include "package/predicted_normals.hpp"
#include "package/quantized_node.hpp"
#include "package/vertex_attributes.hpp"

namespace lodstream::package {

namespace {

constexpr uint8_t kFormat = 1;
constexpr uint32_t kAllFlags = kHasNormals | kHasUvs | kHasColors | kHasVertexData | kProgressive;
constexpr uint32_t kNone = UINT32_MAX;
constexpr uint32_t kMaxPositionBytes = 5, kMaxNormalBytes = 3;
// Triangles before a vertex's first triangle searched for the one across the parallelogram's edge.
constexpr uint32_t kAcrossWindow = 8;
// Decoded coarse coordinates stay within ±2^32 (valid ones within ±2^31), so no chain of predictions from
// hostile residuals (< 2^40) overflows int64.
constexpr int64_t kMaxCoarse = int64_t(1) << 32;

// Calls visit(v, o1, o2, o) for v = 0, 1, ..., V - 1 with v's predictors, all below v (decoded before it in
// vertex order): o1 + o2 - o (parallelogram), o1 alone (o2 == kNone), or none (o1 == kNone: predict from
// vertex v - 1, or cmin for v = 0); the rule is the header comment's. `first` is scratch (V + 1 entries).
// Returns the largest index, which the caller must check against the node's index_end (one at or past
// first_vertex + V, a progressive step's corner in a later step, is never a predictor). O(T + V), one
// branch-free pass over the corners, then per vertex a look at its first triangle and the kAcrossWindow
// triangles before it.
template <class Visit>
uint32_t for_each_prediction(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t V,
                             std::vector<uint32_t>& first, Visit&& visit) {
  // first[v]: the first corner using v (a reverse pass storing unconditionally leaves the smallest; indices
  // past the node land in the spare entry V).
  first.assign(size_t(V) + 1, kNone);
  const uint32_t corners = uint32_t(indices.size());
  uint32_t largest = 0;
  if (first_vertex == 0) {
    for (uint32_t c = corners; c-- > 0;) {
      const uint32_t i = indices[c];
      largest = std::max(largest, i);
      first[std::min(i, V)] = c;
    }
  } else {
    for (uint32_t c = corners; c-- > 0;) {
      largest = std::max(largest, indices[c]);
      if (const uint32_t l = indices[c] - first_vertex; l < V) first[l] = c;
    }
  }
  const uint32_t* idx = indices.data();
  for (uint32_t v = 0; v < V; ++v) {
    const uint32_t corner = first[v];
    if (corner == kNone) {
      visit(v, v > 0 ? v - 1 : kNone, kNone, kNone);
      continue;
    }
    const uint32_t t = corner / 3, k = corner - 3 * t;
    const uint32_t o1 = idx[3 * t + (k == 2 ? 0 : k + 1)] - first_vertex,
                   o2 = idx[3 * t + (k == 0 ? 2 : k - 1)] - first_vertex;
    const bool known1 = o1 < v, known2 = o2 < v;  // chunk-external corners wrap to huge values: unknown
    if (known1 && known2) {
      // The triangle across edge o1-o2 holds o2 -> o1: among the few before t (cache order keeps it close).
      uint32_t o = kNone;
      for (uint32_t back = 1; back <= kAcrossWindow && back <= t && o == kNone; ++back) {
        const uint32_t* u = idx + 3 * (t - back);
        const uint32_t a = u[0] - first_vertex, b = u[1] - first_vertex, c = u[2] - first_vertex;
        if (a == o2 && b == o1) o = c;
        if (b == o2 && c == o1) o = a;
        if (c == o2 && a == o1) o = b;
        if (o >= v) o = kNone;
      }
      if (o != kNone)
        visit(v, o1, o2, o);
      else
        visit(v, o1, kNone, kNone);
    } else if (known1 || known2) {
      visit(v, known1 ? o1 : o2, kNone, kNone);
    } else {
      visit(v, v > 0 ? v - 1 : kNone, kNone, kNone);
    }
  }
  return largest;
}

// Rewrites for_each_prediction's predictors so that every case is the parallelogram c[o1] + c[o2] - c[o] over
// coordinates with an extra entry V holding cmin: o2 = o = o1 for a single predictor, o1 = o2 = o = V for
// none. Lets encoder and decoder predict with one branch-free formula.
void parallelogram_form(uint32_t V, uint32_t& o1, uint32_t& o2, uint32_t& o) {
  if (o1 == kNone) o1 = V;
  if (o2 == kNone) o2 = o = o1;
}

struct Parsed : NodeHeader {
  uint32_t position_bytes = 0, normal_bytes = 0;
  size_t header_size = 0;
  std::span<const uint8_t> position_planes, normal_planes, attribute_stream, locked_stream, index_stream,
      extra;
};

Parsed parse(std::span<const uint8_t> bytes, const std::string& where) {
  ByteReader r(bytes, where);
  Parsed p;
  static_cast<NodeHeader&>(p) = NodeHeader::read(r, kFormat, kAllFlags, bytes.size());
  const uint8_t widths = r.u8();
  p.position_bytes = widths & 15, p.normal_bytes = widths >> 4;
  if (p.position_bytes < 1 || p.position_bytes > kMaxPositionBytes || p.normal_bytes > kMaxNormalBytes ||
      (p.normal_bytes == 0) != !(p.flags & kHasNormals))
    r.fail("invalid residual widths");
  const uint64_t attribute_size = r.varint(), locked_size = r.varint(), index_size = r.varint();
  p.header_size = r.position();
  const uint64_t planes = uint64_t(p.vertices) * (3 * p.position_bytes + 2 * p.normal_bytes);
  const uint64_t fixed = planes + p.extra_size;  // both overflow-free: V ≤ 65536, extra_size < the node size
  if (p.extra_size > r.remaining() || fixed > r.remaining() || attribute_size > r.remaining() - fixed ||
      locked_size > r.remaining() - fixed - attribute_size ||
      index_size != r.remaining() - fixed - attribute_size - locked_size)
    r.fail("stream sizes do not add up to the node size");
  p.position_planes = r.bytes(size_t(3) * p.position_bytes * p.vertices, "position residuals");
  p.normal_planes = r.bytes(size_t(2) * p.normal_bytes * p.vertices, "normal residuals");
  p.attribute_stream = r.bytes(attribute_size, "attribute stream");
  p.locked_stream = r.bytes(locked_size, "locked stream");
  p.index_stream = r.bytes(index_size, "index stream");
  p.extra = r.bytes(p.extra_size, "extra bytes");
  return p;
}

}  // namespace

PredictiveCodec::PredictiveCodec() {
  meshopt_encodeIndexVersion(1);
}

std::vector<uint8_t> PredictiveCodec::encode(const NodeGeometry& g, const PositionGrid& grid) const {
  const QuantizedNode n = quantize_node(g, grid);
  const Mesh& m = *g.mesh;
  const uint32_t V = uint32_t(m.positions.size());
  const uint32_t k = g.position_shift;
  const uint32_t flags = attribute_flags(g);

  // The triangles as the decoder will see them (the index codec may rotate them).
  std::vector<uint8_t> index_stream(meshopt_encodeIndexBufferBound(n.indices.size(), n.index_end));
  index_stream.resize(meshopt_encodeIndexBuffer(index_stream.data(), index_stream.size(), n.indices.data(),
                                                n.indices.size()));
  std::vector<uint32_t> seen(n.indices.size());
  if (meshopt_decodeIndexBuffer(seen.data(), seen.size(), sizeof(uint32_t), index_stream.data(),
                                index_stream.size()) != 0)
    throw Error("node codec: index codec round trip failed");

  // Position residuals in vertex order.
  std::vector<int64_t> c(n.c);
  c.insert(c.end(), std::begin(n.cmin), std::end(n.cmin));
  std::vector<uint64_t> residuals(3 * size_t(V));
  std::vector<uint32_t> first;
  uint64_t largest = 0;
  for_each_prediction(seen, g.first_vertex, V, first, [&](uint32_t v, uint32_t o1, uint32_t o2, uint32_t o) {
    parallelogram_form(V, o1, o2, o);
    for (int a = 0; a < 3; ++a) {
      const int64_t predicted = c[3 * size_t(o1) + a] + c[3 * size_t(o2) + a] - c[3 * size_t(o) + a];
      const uint64_t z = zigzag(c[3 * size_t(v) + a] - predicted);
      residuals[3 * size_t(v) + a] = z;
      largest = std::max(largest, z);
    }
  });
  const uint32_t position_bytes = bytes_for(largest);

  // Normal residuals against the prediction from the decoded positions.
  const std::vector<uint8_t> locked_stream = encode_locked_stream(n, k);
  std::vector<uint64_t> normal_planes;
  uint32_t normal_bytes = 0;
  if (flags & kHasNormals) {
    std::vector<glm::vec3> decoded(V), sum;
    decode_positions(n.c, LockedStream::parse(locked_stream, V, k, "node codec"), grid, decoded.data());
    predicted_normals(seen, g.first_vertex, n.index_end, decoded.data(), V, sum);
    normal_planes = normal_residuals(m.normals, n.order, sum, g.normal_bits, normal_bytes);
  }
  const std::vector<uint8_t> attribute_stream = encode_attribute_stream(flags, g, n);

  ByteWriter w;
  NodeHeader::of(kFormat, flags, g, n).write(w);
  w.u8(static_cast<uint8_t>(position_bytes | normal_bytes << 4));
  w.varint(attribute_stream.size());
  w.varint(locked_stream.size());
  w.varint(index_stream.size());
  put_planes(w.bytes, residuals, 3, position_bytes);
  if (normal_bytes) put_planes(w.bytes, normal_planes, 2, normal_bytes);
  w.raw(attribute_stream);
  w.raw(locked_stream);
  w.raw(index_stream);
  w.raw(g.extra);
  return std::move(w.bytes);
}

DecodedNode PredictiveCodec::decode(std::span<const uint8_t> bytes, const PositionGrid& grid,
                                    const std::string& where) const {
  const Parsed p = parse(bytes, where);
  const uint32_t V = p.vertices;
  const size_t T = p.triangles;
  DecodedNode out;
  out.first_vertex = p.first_vertex;
  out.index_end = p.index_end;
  out.extra.assign(p.extra.begin(), p.extra.end());
  Mesh& m = out.mesh;
  m.indices.resize(3 * T);
  if (meshopt_decodeIndexBuffer(m.indices.data(), m.indices.size(), sizeof(uint32_t), p.index_stream.data(),
                                p.index_stream.size()) != 0)
    throw Error(where + ": corrupted index stream");
  const LockedStream locked = LockedStream::parse(p.locked_stream, V, p.shift, where);

  // Positions: the prediction of the header comment, in vertex order, branch-free: every case is
  // c[o1] + c[o2] - c[o], with o2 = o = o1 for a single predictor and o1 = o2 = o = V (an extra entry holding
  // cmin) for none. The arithmetic wraps (unsigned), so hostile residuals cannot overflow; the results and
  // the indices are range-checked afterwards.
  thread_local std::vector<uint32_t> first;
  thread_local std::vector<int64_t> residual, c;
  residual.resize(3 * size_t(V)), c.resize(3 * (size_t(V) + 1));
  read_planes(p.position_planes.data(), V, 3, p.position_bytes, residual.data());
  const int64_t *rx = residual.data(), *ry = rx + V, *rz = ry + V;
  uint64_t* cu = reinterpret_cast<uint64_t*>(c.data());
  for (int a = 0; a < 3; ++a) cu[3 * size_t(V) + a] = uint64_t(p.cmin[a]);
  const uint32_t max_index = for_each_prediction(
      m.indices, p.first_vertex, V, first, [&](uint32_t v, uint32_t o1, uint32_t o2, uint32_t o) {
        parallelogram_form(V, o1, o2, o);
        const uint64_t *x = cu + 3 * size_t(o1), *y = cu + 3 * size_t(o2), *z = cu + 3 * size_t(o);
        uint64_t* out = cu + 3 * size_t(v);
        out[0] = x[0] + y[0] - z[0] + uint64_t(rx[v]);
        out[1] = x[1] + y[1] - z[1] + uint64_t(ry[v]);
        out[2] = x[2] + y[2] - z[2] + uint64_t(rz[v]);
      });
  bool out_of_range = false;
  for (size_t i = 0; i < 3 * size_t(V); ++i)
    out_of_range |= cu[i] + uint64_t(kMaxCoarse) > 2 * uint64_t(kMaxCoarse);
  if (T > 0 && max_index >= p.index_end)
    throw Error(where + ": index " + std::to_string(max_index) + " out of range");
  if (out_of_range) throw Error(where + ": predicted position out of the grid's range");
  m.positions.resize(V);
  decode_positions(std::span(c).first(3 * size_t(V)), locked, grid, m.positions.data());

  if (p.flags & kHasNormals) {
    thread_local std::vector<glm::vec3> sum;
    predicted_normals(m.indices, p.first_vertex, p.index_end, m.positions.data(), V, sum);
    m.normals.resize(V);
    decode_predicted_normals(sum, p.normal_planes.data(), p.normal_bytes, p.normal_bits, m.normals.data());
  }
  decode_attribute_stream(p.attribute_stream, p.flags, V, p.uv_min, p.uv_extent, out, where);
  return out;
}

NodeSizeBreakdown PredictiveCodec::breakdown(std::span<const uint8_t> bytes, const std::string& where) const {
  const Parsed p = parse(bytes, where);
  NodeSizeBreakdown b;
  b.header = p.header_size;
  b.vertices = p.position_planes.size() + p.normal_planes.size() + p.attribute_stream.size();
  b.locked = p.locked_stream.size();
  b.indices = p.index_stream.size() + p.extra.size();  // extra: a progressive step's chains (connectivity)
  return b;
}

}  // namespace lodstream::package
