#include "package/meshopt_codec.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numeric>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/coarse_positions.hpp"
#include "package/node_header.hpp"
#include "package/octahedral.hpp"
#include "package/vertex_attributes.hpp"

namespace lodstream::package {

namespace {

constexpr uint8_t kFormat = 1;
constexpr uint32_t kWidePositions = 16;  // with vertex_attributes.hpp's attribute flags and kProgressive
constexpr uint32_t kAllFlags =
    kHasNormals | kHasUvs | kHasColors | kHasVertexData | kWidePositions | kProgressive;

// Byte offsets of each attribute inside the interleaved vertex record.
struct Layout {
  size_t position = 0, normal = 0, stride = 0;
  size_t position_size = 0, normal_size = 0;
  AttributeLayout attributes;
};

Layout layout_for(uint32_t flags, uint32_t normal_bits) {
  Layout l;
  l.position_size = (flags & kWidePositions) ? 12 : 6;
  l.normal_size = (flags & kHasNormals) ? (normal_bits <= 8 ? 2 : 4) : 0;
  l.normal = l.position_size;
  l.attributes = attribute_layout(flags, l.position_size + l.normal_size);
  l.stride = (l.attributes.end + 3) & ~size_t(3);
  return l;
}

struct Parsed : NodeHeader {
  size_t header_size = 0;
  std::span<const uint8_t> vertex_stream, locked_stream, index_stream, extra;
};

// The header of a node of node_size bytes and its stream sizes (vertex, locked, index), checked to add up.
Parsed read_layout(ByteReader& r, size_t node_size, uint64_t (&sizes)[3]) {
  Parsed p;
  static_cast<NodeHeader&>(p) = NodeHeader::read(r, kFormat, kAllFlags, node_size);
  const uint64_t extra_size = p.extra_size;
  uint64_t vertex_size = r.varint(), locked_size = r.varint(), index_size = r.varint();
  p.header_size = r.position();
  const uint64_t remaining = node_size - std::min<uint64_t>(node_size, p.header_size);
  if (p.header_size > node_size || extra_size > remaining || vertex_size > remaining - extra_size ||
      locked_size > remaining - extra_size - vertex_size ||
      index_size != remaining - extra_size - vertex_size - locked_size) {
    r.fail("stream sizes do not add up to the node size");
  }
  sizes[0] = vertex_size, sizes[1] = locked_size, sizes[2] = index_size;
  return p;
}

Parsed parse(std::span<const uint8_t> bytes, const std::string& where) {
  ByteReader r(bytes, where);
  uint64_t sizes[3];
  Parsed p = read_layout(r, bytes.size(), sizes);
  const uint64_t vertex_size = sizes[0], locked_size = sizes[1], index_size = sizes[2];
  const uint64_t extra_size = p.extra_size;
  p.vertex_stream = r.bytes(vertex_size, "vertex stream");
  p.locked_stream = r.bytes(locked_size, "locked stream");
  p.index_stream = r.bytes(index_size, "index stream");
  p.extra = r.bytes(extra_size, "extra bytes");
  return p;
}

}  // namespace

MeshoptCodec::MeshoptCodec() {
  meshopt_encodeIndexVersion(1);
}

std::vector<uint8_t> MeshoptCodec::encode(const NodeGeometry& g, const PositionGrid& grid) const {
  if (g.cluster_triangles.size() > 1) throw Error("node codec 1: one cluster per node");
  const QuantizedNode n = quantize_node(g, grid);
  const Mesh& m = *g.mesh;
  const size_t V = m.positions.size();
  const uint32_t k = g.position_shift;
  uint32_t flags = attribute_flags(g);
  for (int a = 0; a < 3; ++a) {
    if (n.cmax[a] - n.cmin[a] > 65535) flags |= kWidePositions;
  }

  const Layout L = layout_for(flags, g.normal_bits);
  std::vector<uint8_t> records(V * L.stride, 0);
  for (size_t v = 0; v < V; ++v) {
    uint8_t* r = records.data() + v * L.stride;
    const uint32_t old = n.order[v];
    for (int a = 0; a < 3; ++a) {
      uint64_t s = static_cast<uint64_t>(n.c[3 * v + a] - n.cmin[a]);
      if (flags & kWidePositions) {
        store_raw(r + 4 * a, static_cast<uint32_t>(s));
      } else {
        store_raw(r + 2 * a, static_cast<uint16_t>(s));
      }
    }
    if (flags & kHasNormals) {
      glm::ivec2 o = oct_encode(m.normals[old], int(g.normal_bits));
      if (L.normal_size == 2) {
        r[L.normal] = static_cast<uint8_t>(static_cast<int8_t>(o.x));
        r[L.normal + 1] = static_cast<uint8_t>(static_cast<int8_t>(o.y));
      } else {
        store_raw(r + L.normal, static_cast<int16_t>(o.x));
        store_raw(r + L.normal + 2, static_cast<int16_t>(o.y));
      }
    }
    put_attributes(r, L.attributes, flags, g, n, old);
  }

  std::vector<uint8_t> vertex_stream(meshopt_encodeVertexBufferBound(V, L.stride));
  vertex_stream.resize(
      meshopt_encodeVertexBuffer(vertex_stream.data(), vertex_stream.size(), records.data(), V, L.stride));
  const std::vector<uint8_t> locked_stream = encode_locked_stream(n, k);
  std::vector<uint8_t> index_stream(meshopt_encodeIndexBufferBound(n.indices.size(), n.index_end));
  index_stream.resize(meshopt_encodeIndexBuffer(index_stream.data(), index_stream.size(), n.indices.data(),
                                                n.indices.size()));

  ByteWriter w;
  NodeHeader::of(kFormat, flags, g, n).write(w);
  w.varint(vertex_stream.size());
  w.varint(locked_stream.size());
  w.varint(index_stream.size());
  w.raw(vertex_stream);
  w.raw(locked_stream);
  w.raw(index_stream);
  w.raw(g.extra);
  return std::move(w.bytes);
}

DecodedNode MeshoptCodec::decode(std::span<const uint8_t> bytes, const PositionGrid& grid,
                                 const std::string& where) const {
  const Parsed p = parse(bytes, where);
  const size_t V = p.vertices, T = p.triangles;
  const Layout L = layout_for(p.flags, p.normal_bits);

  std::vector<uint8_t> records(V * L.stride);
  if (meshopt_decodeVertexBuffer(records.data(), V, L.stride, p.vertex_stream.data(),
                                 p.vertex_stream.size()) != 0) {
    throw Error(where + ": corrupted vertex stream");
  }
  DecodedNode out;
  out.first_vertex = p.first_vertex;
  out.index_end = p.index_end;
  out.extra.assign(p.extra.begin(), p.extra.end());
  Mesh& m = out.mesh;
  m.indices.resize(3 * T);
  if (meshopt_decodeIndexBuffer(m.indices.data(), m.indices.size(), sizeof(uint32_t), p.index_stream.data(),
                                p.index_stream.size()) != 0) {
    throw Error(where + ": corrupted index stream");
  }
  uint32_t max_index = 0;
  for (uint32_t i : m.indices) max_index = std::max(max_index, i);
  if (T > 0 && max_index >= p.index_end)
    throw Error(where + ": index " + std::to_string(max_index) + " out of range");

  // Positions: q = (cmin + stored) * 2^k (+ the k low bits of a locked vertex), coarse_positions.hpp.
  const LockedStream locked = LockedStream::parse(p.locked_stream, V, p.shift, where);
  const bool wide = p.flags & kWidePositions;
  std::vector<int64_t> c(3 * V);
  for (size_t v = 0; v < V; ++v) {
    const uint8_t* r = records.data() + v * L.stride;
    for (int a = 0; a < 3; ++a)
      c[3 * v + a] = p.cmin[a] +
                     (wide ? int64_t(load_raw<uint32_t>(r + 4 * a)) : int64_t(load_raw<uint16_t>(r + 2 * a)));
  }
  m.positions.resize(V);
  decode_positions(c, locked, grid, m.positions.data());
  if (p.flags & kHasNormals) {
    m.normals.resize(V);
    const float inv_scale = 1.0f / static_cast<float>((1 << (p.normal_bits - 1)) - 1);
    for (size_t v = 0; v < V; ++v) {
      const uint8_t* r = records.data() + v * L.stride + L.normal;
      int x, y;
      if (L.normal_size == 2) {
        x = static_cast<int8_t>(r[0]), y = static_cast<int8_t>(r[1]);
      } else {
        x = load_raw<int16_t>(r), y = load_raw<int16_t>(r + 2);
      }
      m.normals[v] = oct_decode(x, y, inv_scale);
    }
  }
  get_attributes(records.data(), L.stride, V, L.attributes, p.flags, p.uv_min, p.uv_extent, out);
  return out;
}

NodeSizeBreakdown MeshoptCodec::layout(std::span<const uint8_t> bytes, size_t node_size,
                                       const std::string& where) const {
  ByteReader r(bytes, where);
  uint64_t sizes[3];
  const Parsed p = read_layout(r, node_size, sizes);
  NodeSizeBreakdown b;
  b.header = p.header_size;
  b.vertices = sizes[0];
  b.locked = sizes[1];
  b.indices = sizes[2] + p.extra_size;  // extra: a progressive step's chains (connectivity)
  b.stored_vertices = p.vertices;
  return b;
}

}  // namespace lodstream::package
