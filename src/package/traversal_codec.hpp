// The third node codec (id 3): connectivity as a traversal (traversal_connectivity.hpp), so that every new
// vertex arrives across a known edge and is predicted by the parallelogram of that edge's triangle; normals
// predicted from the decoded positions (predicted_normals.hpp); residuals as byte planes (byte_planes.hpp)
// that the writer's per-page zstd entropy-codes; UVs, colours and vertex_data as codec 2 stores them
// (vertex_attributes.hpp). Quantization and the locked stream are codec 1's (quantized_node.hpp,
// coarse_positions.hpp): positions decode to the same grid values, locked vertices bit-identically on the
// finest grid.
//
// Nodes whose vertex and triangle order is significant (first_vertex > 0, preserve_order, indices past the
// node, extra bytes: progressive-mesh steps) cannot be renumbered by a traversal: codec 3 stores them as
// codec 2 does (its bytes, format 1) and decodes by the format byte.
//
// Bytes of a traversal node: predictive_node.hpp's layout with format 2 and flags 1 normals, 2 uvs,
//   4 colors, 8 vertex_data, 64 clusters (node_header.hpp); the connectivity stream is the traversal's
//   symbols, the tail its references. Vertices are numbered in traversal order and predicted by the
//   traversal's predictors.
// Records: a page group's clusters encoded as one node (NodeGeometry::cluster_triangles) share one vertex
//   pool, so a vertex that several of its clusters hold is stored and predicted once (a cluster alone
//   stores its border vertices again and predicts them from half their fan); the traversal tags each
//   triangle's cluster and the decoder returns each cluster's triangles as a consecutive range
//   (traversal_connectivity.hpp). A record of progressive steps (order significant) is refused.
#pragma once

#include "package/node_codec.hpp"

namespace lodstream::package {

class TraversalCodec final : public NodeCodec {
 public:
  static constexpr uint32_t kId = 3;
  uint32_t id() const override { return kId; }
  uint32_t max_record_clusters() const override;
  std::vector<uint8_t> encode(const NodeGeometry& geometry, const PositionGrid& grid) const override;
  DecodedNode decode(std::span<const uint8_t> bytes, const PositionGrid& grid,
                     const std::string& where) const override;
  void decode_into(std::span<const uint8_t> bytes, const PositionGrid& grid, const std::string& where,
                   DecodedNode& out) const override;
  NodeSizeBreakdown layout(std::span<const uint8_t> bytes, size_t node_size,
                           const std::string& where) const override;
};

}  // namespace lodstream::package
