// The second node codec (id 2): positions and normals predicted from what the decoder already has, their
// residuals stored as byte planes that the writer's per-page zstd entropy-codes; connectivity, UVs, colours
// and vertex_data as codec 1 stores them (meshoptimizer's index and vertex codecs). Quantization and the
// locked stream are codec 1's (quantized_node.hpp, coarse_positions.hpp), so positions decode to the same
// grid values and locked vertices bit-identically on the finest grid.
//
// Bytes of a node: predictive_node.hpp's layout with format 1 and flags 1 normals, 2 uvs, 4 colors,
//   8 vertex_data, 32 progressive; the connectivity stream is the index stream, the tail the extra bytes.
//   Codec 3 stores the nodes whose order is significant (progressive-mesh steps) this way.
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
//   Residuals c - pred as predictive_node.hpp stores them. Chunk vertices below first_vertex, and a
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
  void decode_into(std::span<const uint8_t> bytes, const PositionGrid& grid, const std::string& where,
                   DecodedNode& out) const override;
  NodeSizeBreakdown layout(std::span<const uint8_t> bytes, size_t node_size,
                           const std::string& where) const override;
};

}  // namespace lodstream::package
