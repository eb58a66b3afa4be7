#include "package/meshopt_codec.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numeric>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/octahedral.hpp"

namespace lodstream::package {

namespace {

constexpr uint8_t kFormat = 1;
constexpr uint32_t kNormals = 1, kUvs = 2, kColors = 4, kVertexData = 8, kWidePositions = 16,
                   kProgressive = 32, kAllFlags = 63;
constexpr size_t kMaxVertices = 65536;
constexpr uint32_t kMaxShift = 24;
constexpr int64_t kMaxGridCoordinate = int64_t(1) << 30;

// Byte offsets of each attribute inside the interleaved vertex record.
struct Layout {
  size_t position = 0, normal = 0, uv = 0, color = 0, data = 0, stride = 0;
  size_t position_size = 0, normal_size = 0;
};

Layout layout_for(uint32_t flags, uint32_t normal_bits) {
  Layout l;
  l.position_size = (flags & kWidePositions) ? 12 : 6;
  l.normal_size = (flags & kNormals) ? (normal_bits <= 8 ? 2 : 4) : 0;
  size_t at = l.position_size;
  l.normal = at, at += l.normal_size;
  l.uv = at, at += (flags & kUvs) ? 4 : 0;
  l.color = at, at += (flags & kColors) ? 4 : 0;
  l.data = at, at += (flags & kVertexData) ? 4 : 0;
  l.stride = (at + 3) & ~size_t(3);
  return l;
}

struct Parsed {
  uint32_t flags = 0, shift = 0, normal_bits = 0, vertices = 0, triangles = 0, first_vertex = 0,
           index_end = 0;
  int64_t cmin[3] = {0, 0, 0};
  glm::vec2 uv_min{0.0f}, uv_extent{0.0f};
  size_t header_size = 0;
  std::span<const uint8_t> vertex_stream, locked_stream, index_stream, extra;
};

Parsed parse(std::span<const uint8_t> bytes, const std::string& where) {
  ByteReader r(bytes, where);
  Parsed p;
  if (r.u8() != kFormat) r.fail("unknown node format");
  p.flags = r.u8();
  if (p.flags & ~kAllFlags) r.fail("unknown node flags");
  p.shift = r.u8();
  if (p.shift > kMaxShift) r.fail("position shift " + std::to_string(p.shift) + " too large");
  p.normal_bits = r.u8();
  if ((p.flags & kNormals) && (p.normal_bits < 4 || p.normal_bits > 16)) r.fail("invalid normal bits");
  uint64_t v = r.varint();
  if (v > kMaxVertices) r.fail("vertex count " + std::to_string(v) + " exceeds 65536");
  p.vertices = static_cast<uint32_t>(v);
  // meshopt's index stream spends at least one byte per triangle, so a count above the node's size is a lie.
  uint64_t t = r.varint();
  if (t > bytes.size()) r.fail("triangle count " + std::to_string(t) + " impossible for a node of this size");
  p.triangles = static_cast<uint32_t>(t);
  uint64_t first = r.varint();
  if (first > UINT32_MAX - p.vertices) r.fail("first vertex out of range");
  p.first_vertex = static_cast<uint32_t>(first);
  p.index_end = p.first_vertex + p.vertices;
  uint64_t extra_size = 0;
  if (p.flags & kProgressive) {
    const uint64_t end = r.varint();
    if (end < p.index_end || end > UINT32_MAX) r.fail("index end out of range");
    p.index_end = static_cast<uint32_t>(end);
    extra_size = r.varint();
  }
  for (int64_t& c : p.cmin) {
    c = r.svarint();
    if (c < -kMaxGridCoordinate * 2 || c > kMaxGridCoordinate * 2) r.fail("grid coordinate out of range");
  }
  if (p.flags & kUvs) {
    p.uv_min = {r.finite_f32("uv"), r.finite_f32("uv")};
    p.uv_extent = {r.finite_f32("uv"), r.finite_f32("uv")};
  }
  uint64_t vertex_size = r.varint(), locked_size = r.varint(), index_size = r.varint();
  p.header_size = r.position();
  if (extra_size > r.remaining() || vertex_size > r.remaining() - extra_size ||
      locked_size > r.remaining() - extra_size - vertex_size ||
      index_size != r.remaining() - extra_size - vertex_size - locked_size) {
    r.fail("stream sizes do not add up to the node size");
  }
  p.vertex_stream = r.bytes(vertex_size, "vertex stream");
  p.locked_stream = r.bytes(locked_size, "locked stream");
  p.index_stream = r.bytes(index_size, "index stream");
  p.extra = r.bytes(extra_size, "extra bytes");
  if (p.shift == 0 && locked_size != 0) throw Error(where + ": locked stream without a position shift");
  return p;
}

template <typename T>
void put(uint8_t* dst, T v) {
  std::memcpy(dst, &v, sizeof v);
}
template <typename T>
T get(const uint8_t* src) {
  T v;
  std::memcpy(&v, src, sizeof v);
  return v;
}

// Packs `bits` low bits of values, LSB first.
class BitWriter {
 public:
  explicit BitWriter(std::vector<uint8_t>& out) : out_(out) {}
  void put(uint32_t value, uint32_t bits) {
    for (uint32_t i = 0; i < bits; ++i) {
      if (bit_ == 0) out_.push_back(0);
      out_.back() |= static_cast<uint8_t>(((value >> i) & 1u) << bit_);
      bit_ = (bit_ + 1) & 7;
    }
  }

 private:
  std::vector<uint8_t>& out_;
  uint32_t bit_ = 0;
};

}  // namespace

MeshoptCodec::MeshoptCodec() {
  meshopt_encodeIndexVersion(1);
}

std::vector<uint8_t> MeshoptCodec::encode(const NodeGeometry& g, const PositionGrid& grid) const {
  if (!g.mesh) throw Error("node codec: no mesh given");
  const Mesh& m = *g.mesh;
  const size_t V = m.positions.size();
  auto invalid = [](const std::string& what) { throw Error("node codec: " + what); };
  if (V > kMaxVertices) invalid(std::to_string(V) + " vertices exceed the 65536 a node may hold");
  if ((m.has_normals() && m.normals.size() != V) || (m.has_uvs() && m.uvs.size() != V) ||
      (m.has_colors() && m.colors.size() != V) || (!g.locked.empty() && g.locked.size() != V) ||
      (!g.vertex_data.empty() && g.vertex_data.size() != V)) {
    invalid("attribute arrays differ in length from positions");
  }
  if (m.indices.size() % 3 != 0) invalid("index count is not a multiple of 3");
  if (g.position_shift > kMaxShift) invalid("position shift above 24");
  if (m.has_normals() && (g.normal_bits < 4 || g.normal_bits > 16)) invalid("normal bits outside 4..16");
  if (!(grid.step > 0.0f) || !std::isfinite(grid.step)) invalid("grid step must be positive and finite");
  const uint64_t vertex_end = uint64_t(g.first_vertex) + V;
  if (vertex_end > UINT32_MAX) invalid("first vertex out of range");
  if (g.index_end != 0 && g.index_end < vertex_end) invalid("index end below the node's last vertex");
  const uint64_t index_end = g.index_end == 0 ? vertex_end : g.index_end;
  for (uint32_t i : m.indices) {
    if (i >= index_end) invalid("index " + std::to_string(i) + " out of range");
  }

  // Vertex order: meshopt's vertex-cache then vertex-fetch order (what its codecs compress best), unless the
  // caller's order is significant. order[new] = old.
  std::vector<uint32_t> indices = m.indices;
  std::vector<uint32_t> order(V);
  std::iota(order.begin(), order.end(), 0u);
  if (g.first_vertex == 0 && !g.preserve_order && V > 0) {
    std::vector<uint32_t> optimized(indices.size());
    meshopt_optimizeVertexCache(optimized.data(), indices.data(), indices.size(), V);
    std::vector<uint32_t> remap(V);
    size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), optimized.data(), optimized.size(), V);
    for (uint32_t& r : remap) {
      if (r == ~0u) r = static_cast<uint32_t>(used++);  // unreferenced vertices keep a place at the end
    }
    for (size_t old = 0; old < V; ++old) order[remap[old]] = static_cast<uint32_t>(old);
    for (size_t i = 0; i < indices.size(); ++i) indices[i] = remap[optimized[i]];
  }

  // Quantization: q = round((p - origin) / step); c = round(q / 2^k) for free vertices, floor(q / 2^k) for
  // locked ones (whose k low bits go to the locked stream).
  const uint32_t k = g.position_shift;
  std::vector<int64_t> q(3 * V), c(3 * V);
  int64_t cmin[3] = {0, 0, 0}, cmax[3] = {0, 0, 0};
  for (size_t v = 0; v < V; ++v) {
    const uint32_t old = order[v];
    const bool locked = !g.locked.empty() && g.locked[old];
    for (int a = 0; a < 3; ++a) {
      double t = std::round((double(m.positions[old][a]) - double(grid.origin[a])) / double(grid.step));
      if (!(std::abs(t) <= double(kMaxGridCoordinate))) invalid("position outside the range of the grid");
      int64_t qa = static_cast<int64_t>(t);
      int64_t ca = (k == 0 || locked) ? (qa >> k) : ((qa + (int64_t(1) << (k - 1))) >> k);
      q[3 * v + a] = qa;
      c[3 * v + a] = ca;
      cmin[a] = v == 0 ? ca : std::min(cmin[a], ca);
      cmax[a] = v == 0 ? ca : std::max(cmax[a], ca);
    }
  }
  uint32_t flags = (m.has_normals() ? kNormals : 0) | (m.has_uvs() ? kUvs : 0) |
                   (m.has_colors() ? kColors : 0) | (g.vertex_data.empty() ? 0 : kVertexData) |
                   (index_end != vertex_end || !g.extra.empty() ? kProgressive : 0);
  for (int a = 0; a < 3; ++a) {
    if (cmax[a] - cmin[a] > 65535) flags |= kWidePositions;
  }
  glm::vec2 uv_min(0.0f), uv_max(0.0f);
  if (m.has_uvs()) {
    uv_min = uv_max = V ? m.uvs[0] : glm::vec2(0.0f);
    for (const glm::vec2& uv : m.uvs) {
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) invalid("non-finite texture coordinate");
      uv_min = glm::min(uv_min, uv);
      uv_max = glm::max(uv_max, uv);
    }
  }
  const glm::vec2 uv_extent = uv_max - uv_min;

  const Layout L = layout_for(flags, g.normal_bits);
  std::vector<uint8_t> records(V * L.stride, 0);
  for (size_t v = 0; v < V; ++v) {
    uint8_t* r = records.data() + v * L.stride;
    const uint32_t old = order[v];
    for (int a = 0; a < 3; ++a) {
      uint64_t s = static_cast<uint64_t>(c[3 * v + a] - cmin[a]);
      if (flags & kWidePositions) {
        put(r + 4 * a, static_cast<uint32_t>(s));
      } else {
        put(r + 2 * a, static_cast<uint16_t>(s));
      }
    }
    if (flags & kNormals) {
      glm::ivec2 o = oct_encode(m.normals[old], int(g.normal_bits));
      if (L.normal_size == 2) {
        r[L.normal] = static_cast<uint8_t>(static_cast<int8_t>(o.x));
        r[L.normal + 1] = static_cast<uint8_t>(static_cast<int8_t>(o.y));
      } else {
        put(r + L.normal, static_cast<int16_t>(o.x));
        put(r + L.normal + 2, static_cast<int16_t>(o.y));
      }
    }
    if (flags & kUvs) {
      for (int a = 0; a < 2; ++a) {
        float t = uv_extent[a] > 0.0f ? (m.uvs[old][a] - uv_min[a]) / uv_extent[a] : 0.0f;
        put(r + L.uv + 2 * a, static_cast<uint16_t>(std::lround(std::clamp(t, 0.0f, 1.0f) * 65535.0f)));
      }
    }
    if (flags & kColors) {
      for (int a = 0; a < 4; ++a) {
        r[L.color + a] = static_cast<uint8_t>(std::lround(std::clamp(m.colors[old][a], 0.0f, 1.0f) * 255.0f));
      }
    }
    if (flags & kVertexData) put(r + L.data, g.vertex_data[old]);
  }

  std::vector<uint8_t> vertex_stream(meshopt_encodeVertexBufferBound(V, L.stride));
  vertex_stream.resize(
      meshopt_encodeVertexBuffer(vertex_stream.data(), vertex_stream.size(), records.data(), V, L.stride));
  std::vector<uint8_t> locked_stream;
  if (k > 0) {
    locked_stream.resize((V + 7) / 8, 0);
    for (size_t v = 0; v < V; ++v) {
      if (!g.locked.empty() && g.locked[order[v]])
        locked_stream[v / 8] |= static_cast<uint8_t>(1u << (v % 8));
    }
    BitWriter bits(locked_stream);
    for (size_t v = 0; v < V; ++v) {
      if (g.locked.empty() || !g.locked[order[v]]) continue;
      for (int a = 0; a < 3; ++a) {
        bits.put(static_cast<uint32_t>(q[3 * v + a] - (c[3 * v + a] << k)), k);
      }
    }
  }
  std::vector<uint8_t> index_stream(meshopt_encodeIndexBufferBound(indices.size(), index_end));
  index_stream.resize(
      meshopt_encodeIndexBuffer(index_stream.data(), index_stream.size(), indices.data(), indices.size()));

  ByteWriter w;
  w.u8(kFormat);
  w.u8(static_cast<uint8_t>(flags));
  w.u8(static_cast<uint8_t>(k));
  w.u8(static_cast<uint8_t>((flags & kNormals) ? g.normal_bits : 0));
  w.varint(V);
  w.varint(indices.size() / 3);
  w.varint(g.first_vertex);
  if (flags & kProgressive) {
    w.varint(index_end);
    w.varint(g.extra.size());
  }
  for (int64_t cm : cmin) w.svarint(cm);
  if (flags & kUvs) {
    w.f32(uv_min.x), w.f32(uv_min.y), w.f32(uv_extent.x), w.f32(uv_extent.y);
  }
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

  // Locked stream: a bit per vertex, then 3k residual bits per locked vertex.
  const uint32_t k = p.shift;
  const uint8_t* locked_bits = nullptr;
  const uint8_t* residuals = nullptr;
  if (k > 0) {
    if (p.locked_stream.size() < (V + 7) / 8) throw Error(where + ": locked stream too short");
    locked_bits = p.locked_stream.data();
    size_t locked_count = 0;
    for (size_t i = 0; i < (V + 7) / 8; ++i) locked_count += std::popcount(locked_bits[i]);
    if (V % 8 && (locked_bits[V / 8] >> (V % 8))) throw Error(where + ": locked bits past the last vertex");
    if (p.locked_stream.size() != (V + 7) / 8 + (locked_count * 3 * k + 7) / 8) {
      throw Error(where + ": locked stream size does not match its locked vertices");
    }
    residuals = locked_bits + (V + 7) / 8;
  }

  // Positions: p = origin + q * step with q = (cmin + stored) * 2^k (+ the k low bits of a locked vertex).
  // One expression for every path, so that equal q give bit-identical positions.
  m.positions.resize(V);
  const bool wide = p.flags & kWidePositions;
  auto stored = [&](size_t v, int a) -> int64_t {
    const uint8_t* r = records.data() + v * L.stride;
    return wide ? int64_t(get<uint32_t>(r + 4 * a)) : int64_t(get<uint16_t>(r + 2 * a));
  };
  auto position = [&](int a, int64_t q) { return grid.origin[a] + static_cast<float>(q) * grid.step; };
  if (k == 0) {
    for (size_t v = 0; v < V; ++v) {
      for (int a = 0; a < 3; ++a) m.positions[v][a] = position(a, p.cmin[a] + stored(v, a));
    }
  } else {
    size_t residual_bit = 0;
    for (size_t v = 0; v < V; ++v) {
      const bool locked = (locked_bits[v / 8] >> (v % 8)) & 1;
      for (int a = 0; a < 3; ++a) {
        int64_t q = (p.cmin[a] + stored(v, a)) * (int64_t(1) << k);
        if (locked) {
          uint32_t low = 0;
          for (uint32_t b = 0; b < k; ++b, ++residual_bit) {
            low |= uint32_t((residuals[residual_bit / 8] >> (residual_bit % 8)) & 1) << b;
          }
          q += low;
        }
        m.positions[v][a] = position(a, q);
      }
    }
  }
  if (p.flags & kNormals) {
    m.normals.resize(V);
    const float inv_scale = 1.0f / static_cast<float>((1 << (p.normal_bits - 1)) - 1);
    for (size_t v = 0; v < V; ++v) {
      const uint8_t* r = records.data() + v * L.stride + L.normal;
      int x, y;
      if (L.normal_size == 2) {
        x = static_cast<int8_t>(r[0]), y = static_cast<int8_t>(r[1]);
      } else {
        x = get<int16_t>(r), y = get<int16_t>(r + 2);
      }
      m.normals[v] = oct_decode(x, y, inv_scale);
    }
  }
  if (p.flags & kUvs) {
    m.uvs.resize(V);
    const glm::vec2 scale = p.uv_extent * (1.0f / 65535.0f);
    for (size_t v = 0; v < V; ++v) {
      const uint8_t* r = records.data() + v * L.stride + L.uv;
      m.uvs[v] = p.uv_min + glm::vec2(get<uint16_t>(r), get<uint16_t>(r + 2)) * scale;
    }
  }
  if (p.flags & kColors) {
    m.colors.resize(V);
    for (size_t v = 0; v < V; ++v) {
      const uint8_t* r = records.data() + v * L.stride + L.color;
      m.colors[v] = glm::vec4(r[0], r[1], r[2], r[3]) * (1.0f / 255.0f);
    }
  }
  if (p.flags & kVertexData) {
    out.vertex_data.resize(V);
    for (size_t v = 0; v < V; ++v) out.vertex_data[v] = get<uint32_t>(records.data() + v * L.stride + L.data);
  }
  return out;
}

NodeSizeBreakdown MeshoptCodec::breakdown(std::span<const uint8_t> bytes, const std::string& where) const {
  const Parsed p = parse(bytes, where);
  NodeSizeBreakdown b;
  b.header = p.header_size;
  b.vertices = p.vertex_stream.size();
  b.locked = p.locked_stream.size();
  b.indices = p.index_stream.size() + p.extra.size();  // extra: a progressive step's chains (connectivity)
  return b;
}

const NodeCodec& default_node_codec() {
  static const MeshoptCodec codec;
  return codec;
}

const NodeCodec& node_codec(uint32_t id) {
  if (id == MeshoptCodec::kId) return default_node_codec();
  throw Error("unknown node codec id " + std::to_string(id));
}

}  // namespace lodstream::package
