#include "package/node_header.hpp"

#include <algorithm>
#include <iterator>
#include <string>

#include "core/error.hpp"
#include "package/vertex_attributes.hpp"

namespace lodstream::package {

NodeHeader NodeHeader::of(uint8_t format, uint32_t flags, const NodeGeometry& g, const QuantizedNode& n) {
  NodeHeader h;
  h.format = format, h.flags = flags, h.shift = g.position_shift, h.normal_bits = g.normal_bits;
  h.vertices = uint32_t(n.order.size()), h.triangles = uint32_t(n.indices.size() / 3);
  h.first_vertex = g.first_vertex;
  h.index_end = n.index_end, h.extra_size = g.extra.size();
  if (h.index_end != h.first_vertex + h.vertices || h.extra_size != 0) h.flags |= kProgressive;
  if (g.cluster_triangles.size() > kMaxRecordClusters)
    throw Error("node codec: more clusters than a record may hold");
  if (g.cluster_triangles.size() > 1) {
    h.flags |= kClusters;
    h.clusters = uint32_t(g.cluster_triangles.size());
    std::copy(g.cluster_triangles.begin(), g.cluster_triangles.end(), h.cluster_counts.begin());
  }
  std::copy(std::begin(n.cmin), std::end(n.cmin), h.cmin);
  h.uv_min = n.uv_min, h.uv_extent = n.uv_extent;
  return h;
}

void NodeHeader::write(ByteWriter& w) const {
  w.u8(format);
  w.u8(static_cast<uint8_t>(flags));
  w.u8(static_cast<uint8_t>(shift));
  w.u8(static_cast<uint8_t>((flags & kHasNormals) ? normal_bits : 0));
  w.varint(vertices);
  w.varint(triangles);
  w.varint(first_vertex);
  if (flags & kProgressive) w.varint(index_end), w.varint(extra_size);
  for (int64_t c : cmin) w.svarint(c);
  if (flags & kHasUvs) w.f32(uv_min.x), w.f32(uv_min.y), w.f32(uv_extent.x), w.f32(uv_extent.y);
  if (flags & kClusters) {
    w.varint(clusters);
    for (size_t c = 0; c + 1 < clusters; ++c) w.varint(cluster_counts[c]);
  }
}

NodeHeader NodeHeader::read(ByteReader& r, uint8_t format, uint32_t known_flags, size_t node_size) {
  NodeHeader h;
  h.format = r.u8();
  if (h.format != format) r.fail("unknown node format");
  h.flags = r.u8();
  if (h.flags & ~known_flags) r.fail("unknown node flags");
  h.shift = r.u8();
  if (h.shift > kMaxPositionShift) r.fail("position shift " + std::to_string(h.shift) + " too large");
  h.normal_bits = r.u8();
  if ((h.flags & kHasNormals) && (h.normal_bits < 4 || h.normal_bits > 16)) r.fail("invalid normal bits");
  const uint64_t v = r.varint();
  if (v > kMaxNodeVertices) r.fail("vertex count " + std::to_string(v) + " exceeds 65536");
  h.vertices = static_cast<uint32_t>(v);
  const uint64_t t = r.varint();
  if (t > node_size) r.fail("triangle count " + std::to_string(t) + " impossible for a node of this size");
  h.triangles = static_cast<uint32_t>(t);
  const uint64_t first = r.varint();
  if (first > UINT32_MAX - h.vertices) r.fail("first vertex out of range");
  h.first_vertex = static_cast<uint32_t>(first);
  h.index_end = h.first_vertex + h.vertices;
  if (h.flags & kProgressive) {
    const uint64_t end = r.varint();
    if (end < h.index_end || end > UINT32_MAX) r.fail("index end out of range");
    h.index_end = static_cast<uint32_t>(end);
    h.extra_size = r.varint();
  }
  for (int64_t& c : h.cmin) {
    c = r.svarint();
    if (c < -kMaxGridCoordinate * 2 || c > kMaxGridCoordinate * 2) r.fail("grid coordinate out of range");
  }
  if (h.flags & kHasUvs) {
    h.uv_min = {r.finite_f32("uv"), r.finite_f32("uv")};
    h.uv_extent = {r.finite_f32("uv"), r.finite_f32("uv")};
  }
  if (h.flags & kClusters) {
    const uint64_t count = r.varint();
    if (count < 2 || count > kMaxRecordClusters)
      r.fail("cluster count " + std::to_string(count) + " invalid");
    h.clusters = uint32_t(count);
    uint64_t sum = 0;
    for (uint64_t c = 0; c + 1 < count; ++c) {
      const uint64_t t = r.varint();
      if (t == 0 || t >= h.triangles - std::min<uint64_t>(h.triangles, sum))
        r.fail("cluster triangle counts invalid");
      h.cluster_counts[c] = uint32_t(t), sum += t;
    }
    h.cluster_counts[count - 1] = h.triangles - uint32_t(sum);
  }
  return h;
}

}  // namespace lodstream::package
