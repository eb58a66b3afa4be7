#include "package/vertex_attributes.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <meshoptimizer.h>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/scratch.hpp"

namespace lodstream::package {

uint32_t attribute_flags(const NodeGeometry& g) {
  const Mesh& m = *g.mesh;
  return (m.has_normals() ? kHasNormals : 0) | (m.has_uvs() ? kHasUvs : 0) |
         (m.has_colors() ? kHasColors : 0) | (g.vertex_data.empty() ? 0 : kHasVertexData);
}

AttributeLayout attribute_layout(uint32_t flags, size_t at) {
  AttributeLayout l;
  l.uv = at, at += (flags & kHasUvs) ? 4 : 0;
  l.color = at, at += (flags & kHasColors) ? 4 : 0;
  l.data = at, at += (flags & kHasVertexData) ? 4 : 0;
  l.end = at;
  return l;
}

void put_attributes(uint8_t* r, const AttributeLayout& l, uint32_t flags, const NodeGeometry& g,
                    const QuantizedNode& n, uint32_t old) {
  const Mesh& m = *g.mesh;
  if (flags & kHasUvs) {
    for (int a = 0; a < 2; ++a) {
      float t = n.uv_extent[a] > 0.0f ? (m.uvs[old][a] - n.uv_min[a]) / n.uv_extent[a] : 0.0f;
      store_raw(r + l.uv + 2 * a, static_cast<uint16_t>(std::lround(std::clamp(t, 0.0f, 1.0f) * 65535.0f)));
    }
  }
  if (flags & kHasColors) {
    for (int a = 0; a < 4; ++a)
      r[l.color + a] = static_cast<uint8_t>(std::lround(std::clamp(m.colors[old][a], 0.0f, 1.0f) * 255.0f));
  }
  if (flags & kHasVertexData) store_raw(r + l.data, g.vertex_data[old]);
}

void get_attributes(const uint8_t* records, size_t stride, size_t V, const AttributeLayout& l, uint32_t flags,
                    glm::vec2 uv_min, glm::vec2 uv_extent, DecodedNode& out) {
  Mesh& m = out.mesh;
  if (flags & kHasUvs) {
    m.uvs.resize(V);
    const glm::vec2 scale = uv_extent * (1.0f / 65535.0f);
    for (size_t v = 0; v < V; ++v) {
      const uint8_t* r = records + v * stride + l.uv;
      m.uvs[v] = uv_min + glm::vec2(load_raw<uint16_t>(r), load_raw<uint16_t>(r + 2)) * scale;
    }
  } else {
    m.uvs.clear();
  }
  if (flags & kHasColors) {
    m.colors.resize(V);
    for (size_t v = 0; v < V; ++v) {
      const uint8_t* r = records + v * stride + l.color;
      m.colors[v] = glm::vec4(r[0], r[1], r[2], r[3]) * (1.0f / 255.0f);
    }
  } else {
    m.colors.clear();
  }
  if (flags & kHasVertexData) {
    out.vertex_data.resize(V);
    for (size_t v = 0; v < V; ++v) out.vertex_data[v] = load_raw<uint32_t>(records + v * stride + l.data);
  } else {
    out.vertex_data.clear();
  }
}

std::vector<uint8_t> encode_attribute_stream(uint32_t flags, const NodeGeometry& g, const QuantizedNode& n) {
  std::vector<uint8_t> stream;
  const AttributeLayout layout = attribute_layout(flags, 0);
  if (layout.end == 0) return stream;
  const size_t V = n.order.size(), stride = (layout.end + 3) & ~size_t(3);
  std::vector<uint8_t> records(V * stride, 0);
  for (size_t v = 0; v < V; ++v) put_attributes(records.data() + v * stride, layout, flags, g, n, n.order[v]);
  stream.resize(meshopt_encodeVertexBufferBound(V, stride));
  stream.resize(meshopt_encodeVertexBuffer(stream.data(), stream.size(), records.data(), V, stride));
  return stream;
}

void decode_attribute_stream(std::span<const uint8_t> stream, uint32_t flags, size_t V, glm::vec2 uv_min,
                             glm::vec2 uv_extent, DecodedNode& out, const std::string& where) {
  const AttributeLayout layout = attribute_layout(flags, 0);
  if (layout.end == 0) {
    if (!stream.empty()) throw Error(where + ": attribute stream without attributes");
    get_attributes(nullptr, 0, V, layout, flags, uv_min, uv_extent, out);  // clears them
    return;
  }
  const size_t stride = (layout.end + 3) & ~size_t(3);
  // Kept across nodes (meshopt overwrites the V records): no allocation and zero-fill a node.
  thread_local std::vector<uint8_t> records;
  grow_scratch(records, V * stride);
  if (meshopt_decodeVertexBuffer(records.data(), V, stride, stream.data(), stream.size()) != 0)
    throw Error(where + ": corrupted attribute stream");
  get_attributes(records.data(), stride, V, layout, flags, uv_min, uv_extent, out);
}

}  // namespace lodstream::package
