#include "package/traversal_codec.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "package/byte_planes.hpp"
#include "package/bytes.hpp"
#include "package/coarse_positions.hpp"
#include "package/node_header.hpp"
#include "package/predicted_normals.hpp"
#include "package/predictive_codec.hpp"
#include "package/quantized_node.hpp"
#include "package/traversal_connectivity.hpp"
#include "package/vertex_attributes.hpp"

namespace lodstream::package {

namespace {

constexpr uint8_t kFormat = 2;
constexpr uint8_t kOrderedFormat = 1;  // codec 2's bytes
constexpr uint32_t kAllFlags = kHasNormals | kHasUvs | kHasColors | kHasVertexData;
constexpr uint32_t kMaxPositionBytes = 5, kMaxNormalBytes = 3;
// Decoded coarse coordinates stay within ±2^32 (valid ones within ±2^31), so no chain of predictions from
// hostile residuals (< 2^40) overflows int64.
constexpr int64_t kMaxCoarse = int64_t(1) << 32;

const PredictiveCodec& ordered_codec() {
  static const PredictiveCodec codec;
  return codec;
}

bool order_is_significant(const NodeGeometry& g) {
  return g.first_vertex > 0 || g.preserve_order || g.index_end > g.mesh->positions.size() || !g.extra.empty();
}

struct Parsed : NodeHeader {
  uint32_t position_bytes = 0, normal_bytes = 0;
  size_t header_size = 0;
  std::span<const uint8_t> position_planes, normal_planes, symbols, references, attribute_stream,
      locked_stream;
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
  const uint64_t attribute_size = r.varint(), locked_size = r.varint(), symbol_size = r.varint();
  p.header_size = r.position();
  const uint64_t planes = uint64_t(p.vertices) * (3 * p.position_bytes + 2 * p.normal_bytes);
  if (planes > r.remaining() || attribute_size > r.remaining() - planes ||
      locked_size > r.remaining() - planes - attribute_size ||
      symbol_size > r.remaining() - planes - attribute_size - locked_size)
    r.fail("stream sizes do not add up to the node size");
  p.position_planes = r.bytes(size_t(3) * p.position_bytes * p.vertices, "position residuals");
  p.normal_planes = r.bytes(size_t(2) * p.normal_bytes * p.vertices, "normal residuals");
  p.attribute_stream = r.bytes(attribute_size, "attribute stream");
  p.locked_stream = r.bytes(locked_size, "locked stream");
  p.symbols = r.bytes(symbol_size, "symbols");
  p.references = r.bytes(r.remaining(), "references");
  return p;
}

}  // namespace

std::vector<uint8_t> TraversalCodec::encode(const NodeGeometry& g, const PositionGrid& grid) const {
  if (g.mesh && order_is_significant(g)) return ordered_codec().encode(g, grid);
  NodeGeometry in_order = g;
  in_order.preserve_order = true;  // the traversal chooses the order
  QuantizedNode n = quantize_node(in_order, grid);
  const Mesh& m = *g.mesh;
  const uint32_t V = uint32_t(m.positions.size());
  const uint32_t k = g.position_shift;
  const uint32_t flags = attribute_flags(g);

  TraversalCode code = encode_traversal(n.indices, V);
  reorder_vertices(n, code.order);
  n.indices = std::move(code.indices);

  std::vector<int64_t> c(n.c);
  c.insert(c.end(), std::begin(n.cmin), std::end(n.cmin));
  std::vector<uint64_t> residuals(3 * size_t(V));
  uint64_t largest = 0;
  for (size_t v = 0; v < V; ++v) {
    const uint32_t* o = &code.predictors[3 * v];
    for (int a = 0; a < 3; ++a) {
      const int64_t predicted = c[3 * size_t(o[0]) + a] + c[3 * size_t(o[1]) + a] - c[3 * size_t(o[2]) + a];
      residuals[3 * v + a] = zigzag(c[3 * v + a] - predicted);
      largest = std::max(largest, residuals[3 * v + a]);
    }
  }
  const uint32_t position_bytes = bytes_for(largest);

  const std::vector<uint8_t> locked_stream = encode_locked_stream(n, k);
  std::vector<uint64_t> normal_planes;
  uint32_t normal_bytes = 0;
  if (flags & kHasNormals) {
    std::vector<glm::vec3> decoded(V), sum;
    decode_positions(n.c, LockedStream::parse(locked_stream, V, k, "node codec"), grid, decoded.data());
    predicted_normals(n.indices, 0, V, decoded.data(), V, sum);
    normal_planes = normal_residuals(m.normals, n.order, sum, g.normal_bits, normal_bytes);
  }
  const std::vector<uint8_t> attribute_stream = encode_attribute_stream(flags, g, n);

  ByteWriter w;
  NodeHeader::of(kFormat, flags, g, n).write(w);
  w.u8(static_cast<uint8_t>(position_bytes | normal_bytes << 4));
  w.varint(attribute_stream.size());
  w.varint(locked_stream.size());
  w.varint(code.symbols.size());
  put_planes(w.bytes, residuals, 3, position_bytes);
  if (normal_bytes) put_planes(w.bytes, normal_planes, 2, normal_bytes);
  w.raw(attribute_stream);
  w.raw(locked_stream);
  w.raw(code.symbols);
  w.raw(code.references);
  return std::move(w.bytes);
}

DecodedNode TraversalCodec::decode(std::span<const uint8_t> bytes, const PositionGrid& grid,
                                   const std::string& where) const {
  if (!bytes.empty() && bytes[0] == kOrderedFormat) return ordered_codec().decode(bytes, grid, where);
  const Parsed p = parse(bytes, where);
  const uint32_t V = p.vertices;
  DecodedNode out;
  out.first_vertex = 0;
  out.index_end = V;
  Mesh& m = out.mesh;
  m.indices.resize(3 * size_t(p.triangles));
  thread_local std::vector<uint32_t> predictors;
  predictors.resize(3 * size_t(V));
  decode_traversal(p.symbols, p.references, p.triangles, V, m.indices.data(), predictors.data(), where);
  const LockedStream locked = LockedStream::parse(p.locked_stream, V, p.shift, where);

  // Positions in traversal order: c[v] = c[o1] + c[o2] - c[o] + residual, with entry V holding cmin. The
  // arithmetic wraps (unsigned), so hostile residuals cannot overflow; the results are range-checked after.
  thread_local std::vector<int64_t> residual, c;
  residual.resize(3 * size_t(V)), c.resize(3 * (size_t(V) + 1));
  read_planes(p.position_planes.data(), V, 3, p.position_bytes, residual.data());
  const int64_t *rx = residual.data(), *ry = rx + V, *rz = ry + V;
  uint64_t* cu = reinterpret_cast<uint64_t*>(c.data());
  for (int a = 0; a < 3; ++a) cu[3 * size_t(V) + a] = uint64_t(p.cmin[a]);
  const uint32_t* o = predictors.data();
  for (uint32_t v = 0; v < V; ++v, o += 3) {
    const uint64_t *x = cu + 3 * size_t(o[0]), *y = cu + 3 * size_t(o[1]), *z = cu + 3 * size_t(o[2]);
    uint64_t* to = cu + 3 * size_t(v);
    to[0] = x[0] + y[0] - z[0] + uint64_t(rx[v]);
    to[1] = x[1] + y[1] - z[1] + uint64_t(ry[v]);
    to[2] = x[2] + y[2] - z[2] + uint64_t(rz[v]);
  }
  bool out_of_range = false;
  for (size_t i = 0; i < 3 * size_t(V); ++i)
    out_of_range |= cu[i] + uint64_t(kMaxCoarse) > 2 * uint64_t(kMaxCoarse);
  if (out_of_range) throw Error(where + ": predicted position out of the grid's range");
  m.positions.resize(V);
  decode_positions(std::span(c).first(3 * size_t(V)), locked, grid, m.positions.data());

  if (p.flags & kHasNormals) {
    thread_local std::vector<glm::vec3> sum;
    predicted_normals(m.indices, 0, V, m.positions.data(), V, sum);
    m.normals.resize(V);
    decode_predicted_normals(sum, p.normal_planes.data(), p.normal_bytes, p.normal_bits, m.normals.data());
  }
  decode_attribute_stream(p.attribute_stream, p.flags, V, p.uv_min, p.uv_extent, out, where);
  return out;
}

NodeSizeBreakdown TraversalCodec::breakdown(std::span<const uint8_t> bytes, const std::string& where) const {
  if (!bytes.empty() && bytes[0] == kOrderedFormat) return ordered_codec().breakdown(bytes, where);
  const Parsed p = parse(bytes, where);
  NodeSizeBreakdown b;
  b.header = p.header_size;
  b.vertices = p.position_planes.size() + p.normal_planes.size() + p.attribute_stream.size();
  b.locked = p.locked_stream.size();
  b.indices = p.symbols.size() + p.references.size();
  return b;
}

}  // namespace lodstream::package
