// What every node codec does first: validate a NodeGeometry, choose the stored vertex order and quantize the
// positions onto the representation's grid (the rule of node_codec.hpp), then the UV box. Shared by the
// codecs so that a vertex that two codecs store decodes to the same grid value.
//
// How precision is spent. q = round((p - origin) / step) on the representation's grid (finest step, error per
// axis ≤ step/2). A free vertex stores c = round(q / 2^k) and decodes to c * 2^k (error per axis ≤ step/2 +
// 2^k step/2); a locked vertex stores c = floor(q / 2^k) plus its k low bits (coarse_positions.hpp) and
// decodes to q exactly.
#pragma once

#include <cstdint>
#include <vector>

#include "package/node_codec.hpp"

namespace lodstream::package {

constexpr size_t kMaxNodeVertices = 65536;
constexpr uint32_t kMaxPositionShift = 24;
constexpr int64_t kMaxGridCoordinate = int64_t(1) << 30;
// The most clusters one record holds (NodeGeometry::cluster_triangles; a DAG group's input clusters are about
// 8, the bake splits larger page groups; 31: a cluster tag fits a traversal symbol's 5 high bits,
// traversal_connectivity.hpp).
constexpr uint32_t kMaxRecordClusters = 31;

struct QuantizedNode {
  std::vector<uint32_t> order;    // order[new] = the caller's vertex
  std::vector<uint32_t> indices;  // the triangles in the new numbering
  uint32_t index_end = 0;         // every index is below it (NodeGeometry::index_end, or first_vertex + V)
  std::vector<int64_t> q, c;      // per new vertex, x y z: finest-grid and stored (coarse) coordinates
  std::vector<uint8_t> locked;    // per new vertex: 1 = locked
  int64_t cmin[3] = {0, 0, 0}, cmax[3] = {0, 0, 0};
  glm::vec2 uv_min{0.0f}, uv_extent{0.0f};  // the node's UV box (zero without UVs)
};

// Validates (throws lodstream::Error "node codec: ..." on the errors NodeCodec::encode lists, and cluster
// triangle counts that are more than kMaxRecordClusters, zero or do not add up to the triangles), reorders
// for meshopt's codecs (vertex-cache, then vertex-fetch order: vertices in first-use order) unless
// first_vertex > 0 or preserve_order, and quantizes. Cost: O(V + T) plus meshopt's reordering.
QuantizedNode quantize_node(const NodeGeometry& geometry, const PositionGrid& grid);

// quantize_node in two steps, for a codec that chooses its own vertex order between them: order_node
// validates (the same errors, but for positions outside the grid's range) and sets order, indices and
// index_end; the codec may then replace order and indices (order[new] = the geometry's vertex);
// quantize_positions quantizes the vertices `order` lists (q, c, locked, cmin, cmax; throws lodstream::Error
// for one outside the grid's range: vertices left out are not stored, so not checked) and sets the UV box.
// Costs: O(V + T) plus meshopt's reordering, and O(V).
QuantizedNode order_node(const NodeGeometry& geometry, const PositionGrid& grid);
void quantize_positions(const NodeGeometry& geometry, const PositionGrid& grid, QuantizedNode& node);

}  // namespace lodstream::package
