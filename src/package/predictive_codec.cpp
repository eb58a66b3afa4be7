#include "package/predictive_codec.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cstring>
#include <iterator>
#include <type_traits>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/coarse_positions.hpp"
#include "package/node_header.hpp"
#include "package/octahedral.hpp"
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

uint64_t zigzag(int64_t v) {
  return (static_cast<uint64_t>(v) << 1) ^ static_cast<uint64_t>(v >> 63);
}
int64_t unzigzag(uint64_t v) {
  return static_cast<int64_t>(v >> 1) ^ -static_cast<int64_t>(v & 1);
}
uint32_t bytes_for(uint64_t largest) {
  uint32_t n = 1;
  while (n < 8 && (largest >> (8 * n)) != 0) ++n;
  return n;
}

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

// Area-weighted vertex normals of the node's own triangles (those whose corners are all in the node), over
// `positions`: sum of cross(p1 - p0, p2 - p0). `index_end` bounds the indices (checked by the caller); when
// it is first_vertex + V (every node but a progressive step) no corner lies outside and the loop tests none.
// O(T + V).
void predicted_normals(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t index_end,
                       const glm::vec3* positions, uint32_t V, std::vector<glm::vec3>& sum) {
  sum.assign(V, glm::vec3(0.0f));
  auto accumulate = [&](auto all_inside) {
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
      const uint32_t a = indices[i] - first_vertex, b = indices[i + 1] - first_vertex,
                     c = indices[i + 2] - first_vertex;
      if (!all_inside && (a >= V || b >= V || c >= V)) continue;
      const glm::vec3 n = glm::cross(positions[b] - positions[a], positions[c] - positions[a]);
      sum[a] += n, sum[b] += n, sum[c] += n;
    }
  };
  if (first_vertex == 0 && index_end == V)
    accumulate(std::true_type{});
  else
    accumulate(std::false_type{});
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

// Unzigzags `count` values of `components` components each, stored as `width` byte planes (byte b of
// component a at plane b * components + a), into out[a * count + i] (one array per component, so each loop
// is a plain pass the compiler can vectorize). Cost: O(count * components * width).
template <typename T>
void read_planes(const uint8_t* planes, size_t count, uint32_t components, uint32_t width, T* out) {
  for (uint32_t a = 0; a < components; ++a) {
    const uint8_t* low = planes + a * count;
    T* o = out + a * count;
    if (width == 1) {
      for (size_t i = 0; i < count; ++i) o[i] = T(int32_t(low[i] >> 1) ^ -int32_t(low[i] & 1));
    } else if (width == 2) {
      const uint8_t* high = planes + (components + a) * count;
      for (size_t i = 0; i < count; ++i) {
        const uint32_t z = low[i] | uint32_t(high[i]) << 8;
        o[i] = T(int32_t(z >> 1) ^ -int32_t(z & 1));
      }
    } else {
      for (size_t i = 0; i < count; ++i) {
        uint64_t value = 0;
        for (uint32_t b = 0; b < width; ++b)
          value |= uint64_t(planes[(b * components + a) * count + i]) << (8 * b);
        o[i] = T(unzigzag(value));
      }
    }
  }
}

void put_planes(std::vector<uint8_t>& out, const std::vector<uint64_t>& values, uint32_t components,
                uint32_t width) {
  const size_t count = values.size() / components;
  const size_t at = out.size();
  out.resize(at + values.size() * width);
  for (size_t i = 0; i < count; ++i)
    for (uint32_t a = 0; a < components; ++a)
      for (uint32_t b = 0; b < width; ++b)
        out[at + (b * components + a) * count + i] = uint8_t(values[components * i + a] >> (8 * b));
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
  std::vector<uint64_t> normal_residuals;
  uint32_t normal_bytes = 0;
  if (flags & kHasNormals) {
    const std::vector<uint8_t> locked = encode_locked_stream(n, k);
    std::vector<glm::vec3> decoded(V), sum;
    decode_positions(n.c, LockedStream::parse(locked, V, k, "node codec"), grid, decoded.data());
    predicted_normals(seen, g.first_vertex, n.index_end, decoded.data(), V, sum);
    normal_residuals.resize(2 * size_t(V));
    largest = 0;
    for (uint32_t v = 0; v < V; ++v) {
      const glm::ivec2 truth = oct_encode(m.normals[n.order[v]], int(g.normal_bits));
      const glm::ivec2 guess = oct_encode(sum[v], int(g.normal_bits));
      for (int a = 0; a < 2; ++a) {
        normal_residuals[2 * size_t(v) + a] = zigzag(truth[a] - guess[a]);
        largest = std::max(largest, normal_residuals[2 * size_t(v) + a]);
      }
    }
    normal_bytes = bytes_for(largest);
  }

  // UVs, colours, vertex_data: meshopt's vertex codec over records in vertex order.
  std::vector<uint8_t> attribute_stream;
  const AttributeLayout layout = attribute_layout(flags, 0);
  if (layout.end > 0) {
    const size_t stride = (layout.end + 3) & ~size_t(3);
    std::vector<uint8_t> records(V * stride, 0);
    for (uint32_t v = 0; v < V; ++v)
      put_attributes(records.data() + v * stride, layout, flags, g, n, n.order[v]);
    attribute_stream.resize(meshopt_encodeVertexBufferBound(V, stride));
    attribute_stream.resize(meshopt_encodeVertexBuffer(attribute_stream.data(), attribute_stream.size(),
                                                       records.data(), V, stride));
  }
  const std::vector<uint8_t> locked_stream = encode_locked_stream(n, k);

  ByteWriter w;
  NodeHeader::of(kFormat, flags, g, n).write(w);
  w.u8(static_cast<uint8_t>(position_bytes | normal_bytes << 4));
  w.varint(attribute_stream.size());
  w.varint(locked_stream.size());
  w.varint(index_stream.size());
  put_planes(w.bytes, residuals, 3, position_bytes);
  if (normal_bytes) put_planes(w.bytes, normal_residuals, 2, normal_bytes);
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
    thread_local std::vector<int32_t> normal_residual;
    predicted_normals(m.indices, p.first_vertex, p.index_end, m.positions.data(), V, sum);
    normal_residual.resize(2 * size_t(V));
    read_planes(p.normal_planes.data(), V, 2, p.normal_bytes, normal_residual.data());
    m.normals.resize(V);
    const int bits = int(p.normal_bits);
    const float inv_scale = 1.0f / static_cast<float>((1 << (bits - 1)) - 1);
    for (uint32_t v = 0; v < V; ++v) {
      const glm::ivec2 guess = oct_encode(sum[v], bits);
      // oct_decode clamps; residuals of a valid node are below 2^17, hostile ones are clamped first.
      const int x = guess.x + std::clamp(normal_residual[v], -(1 << 18), 1 << 18);
      const int y = guess.y + std::clamp(normal_residual[size_t(V) + v], -(1 << 18), 1 << 18);
      m.normals[v] = oct_decode(x, y, inv_scale);
    }
  }

  const AttributeLayout layout = attribute_layout(p.flags, 0);
  if (layout.end > 0) {
    const size_t stride = (layout.end + 3) & ~size_t(3);
    std::vector<uint8_t> records(V * stride);
    if (meshopt_decodeVertexBuffer(records.data(), V, stride, p.attribute_stream.data(),
                                   p.attribute_stream.size()) != 0)
      throw Error(where + ": corrupted attribute stream");
    get_attributes(records.data(), stride, V, layout, p.flags, p.uv_min, p.uv_extent, out);
  } else if (!p.attribute_stream.empty()) {
    throw Error(where + ": attribute stream without attributes");
  }
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
