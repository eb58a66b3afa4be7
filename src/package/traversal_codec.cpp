#include "package/traversal_codec.hpp"

#include <algorithm>

#include "package/predictive_codec.hpp"
#include "package/predictive_node.hpp"
#include "package/quantized_node.hpp"
#include "package/scratch.hpp"
#include "package/traversal_connectivity.hpp"
#include "package/vertex_attributes.hpp"

namespace lodstream::package {

namespace {

constexpr uint8_t kFormat = 2;
constexpr uint8_t kOrderedFormat = 1;  // codec 2's bytes
constexpr uint32_t kAllFlags =
    kHasNormals | kHasUvs | kHasColors | kHasVertexData | kClusters | kPlanePrediction | kMultiParallelogram;

const PredictiveCodec& ordered_codec() {
  static const PredictiveCodec codec;
  return codec;
}

bool order_is_significant(const NodeGeometry& g) {
  return g.first_vertex > 0 || g.preserve_order || g.index_end > g.mesh->positions.size() || !g.extra.empty();
}

}  // namespace

uint32_t TraversalCodec::max_record_clusters() const {
  return kMaxRecordClusters;
}

std::vector<uint8_t> TraversalCodec::encode(const NodeGeometry& g, const PositionGrid& grid) const {
  if (g.mesh && order_is_significant(g)) return ordered_codec().encode(g, grid);
  NodeGeometry in_order = g;
  in_order.preserve_order = true;  // the traversal chooses the order
  QuantizedNode n = order_node(in_order, grid);
  const Mesh& m = *g.mesh;
  const uint32_t V = uint32_t(m.positions.size());
  const uint32_t flags = attribute_flags(g);

  // The vertices quantized straight in traversal order (no copy of them renumbered).
  TraversalCode code = encode_traversal(n.indices, V, g.cluster_triangles);
  n.order = std::move(code.order);
  n.indices = std::move(code.indices);
  quantize_positions(in_order, grid, n);
  const std::vector<uint8_t> locked_stream = encode_locked_stream(n, g.position_shift);
  // The multi-parallelogram predictors as the decoder will find them: from the decoder's own traversal.
  const uint32_t T = uint32_t(n.indices.size() / 3);
  std::vector<uint32_t> indices(n.indices.size()), predictors(3 * (size_t(V) + 1));
  Parallelograms extra;
  decode_traversal(code.symbols, code.references, T, V, indices.data(), predictors.data(), "node codec",
                   g.cluster_triangles, &extra);
  return write_predictive_node(
      NodeHeader::of(kFormat, flags, g, n),
      predictive_residuals(g, n, code.predictors, predictors, &extra, n.indices, locked_stream, grid),
      encode_attribute_stream(flags, g, n), locked_stream, code.symbols, code.references);
}

DecodedNode TraversalCodec::decode(std::span<const uint8_t> bytes, const PositionGrid& grid,
                                   const std::string& where) const {
  DecodedNode out;
  decode_into(bytes, grid, where, out);
  return out;
}

void TraversalCodec::decode_into(std::span<const uint8_t> bytes, const PositionGrid& grid,
                                 const std::string& where, DecodedNode& out) const {
  if (!bytes.empty() && bytes[0] == kOrderedFormat) {
    ordered_codec().decode_into(bytes, grid, where, out);
    return;
  }
  const PredictiveNode p = PredictiveNode::parse(bytes, kFormat, kAllFlags, where);
  const uint32_t V = p.vertices;
  // What the node may not hold cleared (capacity kept); the rest overwritten (the attributes by
  // decode_predicted_vertices, which clears those the node lacks: resized from the last record's count,
  // they are zero-filled only where they grow).
  out.mesh.material = 0, out.extra.clear();
  out.first_vertex = 0, out.index_end = V;
  out.mesh.indices.resize(3 * size_t(p.triangles));  // zero-fills only beyond the size it had
  thread_local std::vector<uint32_t> predictors;
  grow_scratch(predictors, 3 * (size_t(V) + 1));
  thread_local Parallelograms extra;
  Parallelograms* const multi = p.flags & kMultiParallelogram ? &extra : nullptr;
  decode_traversal(p.connectivity, p.tail, p.triangles, V, out.mesh.indices.data(), predictors.data(), where,
                   p.cluster_triangles(), multi);
  decode_predicted_vertices(p, predictors, multi, grid, out, where);
  out.cluster_triangles.assign(p.cluster_triangles().begin(), p.cluster_triangles().end());
}

NodeSizeBreakdown TraversalCodec::layout(std::span<const uint8_t> bytes, size_t node_size,
                                         const std::string& where) const {
  if (!bytes.empty() && bytes[0] == kOrderedFormat) return ordered_codec().layout(bytes, node_size, where);
  uint64_t tail = 0;
  NodeSizeBreakdown b = PredictiveNode::layout(bytes, node_size, kFormat, kAllFlags, where, &tail);
  b.tail = tail;  // the references
  return b;
}

}  // namespace lodstream::package
