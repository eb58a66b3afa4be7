// The first fields of every node codec's bytes (each codec appends its own fields and streams):
//   u8 format, u8 flags (vertex_attributes.hpp's attribute flags plus the codec's own), u8 position_shift k,
//   u8 normal_bits (0 without normals), varint vertex count V (≤ 65536), varint triangle count T, varint
//   first_vertex, [progressive (flag 32): varint index_end, varint size of the extra bytes], svarint cmin[3]
//   (the node's smallest coarse coordinates), [with UVs: f32 uv_min[2], f32 uv_extent[2]], [a record of
//   several clusters (flag 64): varint cluster count C (2..kMaxRecordClusters = 31), then the triangle counts
//   of clusters 0..C-2 (varints; the last cluster has the rest, at least one triangle each)].
// Each codec stores the extra bytes (NodeGeometry::extra) last, after its streams.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>

#include "package/bytes.hpp"
#include "package/quantized_node.hpp"

namespace lodstream::package {

// Flag of a node whose indices reach past its own vertices or that carries extra bytes (progressive meshes).
constexpr uint32_t kProgressive = 32;
// Flag of a record of several clusters (NodeGeometry::cluster_triangles).
constexpr uint32_t kClusters = 64;

struct NodeHeader {
  uint8_t format = 0;
  uint32_t flags = 0, shift = 0, normal_bits = 0, vertices = 0, triangles = 0, first_vertex = 0;
  uint32_t index_end = 0;  // first_vertex + V unless progressive
  uint64_t extra_size = 0;
  int64_t cmin[3] = {0, 0, 0};
  glm::vec2 uv_min{0.0f}, uv_extent{0.0f};
  // With kClusters: the triangle counts of its C clusters (adding up to triangles) in cluster_counts[0 .. C),
  // C = clusters; 0 otherwise. A fixed array, not a vector: every record's header is read twice (its page's
  // layout, then its decode), and a vector was allocated and freed each time (motorBike's `bench decode
  // --runs 1` under callgrind: PredictiveNode::parse and layout 1.28 -> 1.17 M instructions).
  uint32_t clusters = 0;
  std::array<uint32_t, kMaxRecordClusters> cluster_counts{};
  std::span<const uint32_t> cluster_triangles() const { return {cluster_counts.data(), clusters}; }

  // The header of a quantized node (quantized_node.hpp) of `geometry`; adds kProgressive to `flags` when the
  // node's indices reach past its vertices or it carries extra bytes, and kClusters for a record of two
  // clusters or more (throws lodstream::Error for more than kMaxRecordClusters, which quantize_node refuses
  // first).
  static NodeHeader of(uint8_t format, uint32_t flags, const NodeGeometry& geometry,
                       const QuantizedNode& node);
  void write(ByteWriter& w) const;
  // Reads and validates: the format must be `format`, flags within `known_flags`, shift ≤ 24, normal bits in
  // 4..16 with normals, V ≤ 65536, T ≤ node_size (every codec spends at least a byte per triangle),
  // first_vertex + V < 2^32, first_vertex + V ≤ index_end < 2^32, cmin within the grid's range, finite UV
  // box, cluster counts (2..kMaxRecordClusters clusters of at least one triangle, adding up to T). Throws
  // through r.fail.
  static NodeHeader read(ByteReader& r, uint8_t format, uint32_t known_flags, size_t node_size);
};

}  // namespace lodstream::package
