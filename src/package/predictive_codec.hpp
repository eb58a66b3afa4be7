// The second node codec (id 2): positions and normals predicted from what the decoder already has, their
// residuals stored as byte planes that the writer's per-page zstd entropy-codes; connectivity, UVs, colours
// and vertex_data as codec 1 stores them (meshoptimizer's index and vertex codecs). Quantization and the
// locked stream are codec 1's (quantized_node.hpp, coarse_positions.hpp), so positions decode to the same
// grid values and locked vertices bit-identically on the finest grid.
//
// Bytes of a node:
//   the common header (node_header.hpp) with format 1 and flags 1 normals, 2 uvs, 4 colors, 8 vertex_data,
//   32 progressive; u8 widths (low nibble: bytes per position residual wp, 1..5; high nibble: bytes per
//   normal residual wn, 0..3); varint sizes of the attribute, locked and index streams; then the position
//   planes (3 wp V bytes), the normal planes (2 wn V bytes), the attribute, locked and index streams;
//   [progressive: the extra bytes].
// Index stream: meshopt_encodeIndexBuffer (version 1). The decoder decodes it first; everything below walks
//   the decoded triangles, so encoder and decoder predict from the same data.
// Positions (parallelogram prediction, Touma & Gotsman 1998, "Triangle Mesh Compression", GI'98): the
//   coarse coordinates c (quantized_node.hpp) are decoded in vertex order (meshopt's vertex-fetch order:
//   first use by the triangles). Vertex v is predicted from its first triangle t (in decoded order), with
//   o1, o2 its other corners, from vertices below v only:
//     o1, o2 < v, and one of the 8 triangles before t holds edge o2 -> o1 with a third corner o < v:
//                               pred = c[o1] + c[o2] - c[o]   (the parallelogram across edge o1-o2)
//     else o1 or o2 < v:        pred = c[that corner]
//     else:                     pred = c[v - 1], or cmin for v = 0 (also for vertices no triangle uses).
//   Residual c - pred is stored zigzag-mapped, byte b of axis a of vertex v at plane 3b + a, offset v
//   (equal bytes together, so zstd models low and high bytes apart). Chunk vertices below first_vertex, and a
//   progressive step's corners at or past first_vertex + V (in later steps), are not in the node: never
//   predictors. The decode is one branch-free pass over the corners (first corner of each vertex) and one
//   pass over the vertices; no hash maps.
// Normals: predicted from the decoded positions, residuals as byte planes (predicted_normals.hpp).
#pragma once

#include "package/node_codec.hpp"

namespace lodstream::package {

class PredictiveCodec final : public NodeCodec {
 public:
  static constexpr uint32_t kId = 2;
  PredictiveCodec();
  uint32_t id() const override { return kId; }
  std::vector<uint8_t> encode(const NodeGeometry& geometry, const PositionGrid& grid) const override;
  DecodedNode decode(std::span<const uint8_t> bytes, const PositionGrid& grid,
                     const std::string& where) const override;
  NodeSizeBreakdown breakdown(std::span<const uint8_t> bytes, const std::string& where) const override;
};

}  // namespace lodstream::package
