#include "package/predictive_codec.hpp"

#include <meshoptimizer.h>

#include <algorithm>

#include "core/error.hpp"
#include "package/coarse_positions.hpp"
#include "package/predictive_node.hpp"
#include "package/quantized_node.hpp"
#include "package/scratch.hpp"
#include "package/vertex_attributes.hpp"

namespace lodstream::package {

namespace {

constexpr uint8_t kFormat = 1;
constexpr uint32_t kAllFlags =
    kHasNormals | kHasUvs | kHasColors | kHasVertexData | kProgressive | kPlanePrediction;
constexpr uint32_t kNone = UINT32_MAX;
// Triangles before a vertex's first triangle searched for the one across the parallelogram's edge.
constexpr uint32_t kAcrossWindow = 8;

// Calls visit(v, o1, o2, o) for v = 0, 1, ..., V - 1 with v's predictors, all below v (decoded before it in
// vertex order): o1 + o2 - o (parallelogram), o1 alone (o2 == kNone), or none (o1 == kNone: predict from
// vertex v - 1, or cmin for v = 0); the rule is the header comment's. `first` is scratch (V + 1 entries).
// Returns the largest index, which the caller must check against the node's index_end (one at or past
// first_vertex + V, a progressive step's corner in a later step, is never a predictor). O(T + V), one
// branch-free pass over the corners, then per vertex a look at its first triangle and the kAcrossWindow
// triangles before it.
template <class Visit>
uint32_t for_each_prediction(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t V,
                             std::vector<uint32_t>& first, Visit&& visit) {
  // first[v]: the first corner using v (a reverse pass storing unconditionally leaves the smallest; indices
  // outside the node, past it or below first_vertex (wrapping), land in the spare entry V). Stored without a
  // branch past the first vertex too (progressive steps), whose corners outside the node mispredicted it
  // (motorBike's `bench decode --runs 1` under callgrind --branch-sim=yes, predictors_of: 39,971 -> 16,791
  // mispredicted conditional branches, instructions 1.24 -> 1.26 M).
  first.assign(size_t(V) + 1, kNone);
  const uint32_t corners = uint32_t(indices.size());
  uint32_t largest = 0;
  if (first_vertex == 0) {
    for (uint32_t c = corners; c-- > 0;) {
      const uint32_t i = indices[c];
      largest = std::max(largest, i);
      first[std::min(i, V)] = c;
    }
  } else {
    for (uint32_t c = corners; c-- > 0;) {
      largest = std::max(largest, indices[c]);
      first[std::min(indices[c] - first_vertex, V)] = c;
    }
  }
  const uint32_t* idx = indices.data();
  for (uint32_t v = 0; v < V; ++v) {
    const uint32_t corner = first[v];
    if (corner == kNone) {
      visit(v, v > 0 ? v - 1 : kNone, kNone, kNone);
      continue;
    }
    const uint32_t t = corner / 3, k = corner - 3 * t;
    const uint32_t o1 = idx[3 * t + (k == 2 ? 0 : k + 1)] - first_vertex,
                   o2 = idx[3 * t + (k == 0 ? 2 : k - 1)] - first_vertex;
    const bool known1 = o1 < v, known2 = o2 < v;  // chunk-external corners wrap to huge values: unknown
    if (known1 && known2) {
      // The triangle across edge o1-o2 holds o2 -> o1: among the few before t (cache order keeps it close).
      uint32_t o = kNone;
      for (uint32_t back = 1; back <= kAcrossWindow && back <= t && o == kNone; ++back) {
        const uint32_t* u = idx + 3 * (t - back);
        const uint32_t a = u[0] - first_vertex, b = u[1] - first_vertex, c = u[2] - first_vertex;
        if (a == o2 && b == o1) o = c;
        if (b == o2 && c == o1) o = a;
        if (c == o2 && a == o1) o = b;
        if (o >= v) o = kNone;
      }
      if (o != kNone)
        visit(v, o1, o2, o);
      else
        visit(v, o1, kNone, kNone);
    } else if (known1 || known2) {
      visit(v, known1 ? o1 : o2, kNone, kNone);
    } else {
      visit(v, v > 0 ? v - 1 : kNone, kNone, kNone);
    }
  }
  return largest;
}

// Rewrites for_each_prediction's predictors so that every case is the parallelogram c[o1] + c[o2] - c[o] over
// coordinates with an extra entry V holding cmin: o2 = o = o1 for a single predictor, o1 = o2 = o = V for
// none. Lets encoder and decoder predict with one branch-free formula.
void parallelogram_form(uint32_t V, uint32_t& o1, uint32_t& o2, uint32_t& o) {
  if (o1 == kNone) o1 = V;
  if (o2 == kNone) o2 = o = o1;
}

// The predictors (predictive_node.hpp) of every vertex by for_each_prediction's rule into the first 3V
// entries of `predictors` (grow_scratch: it may hold more); returns the largest index. O(T + V).
uint32_t predictors_of(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t V,
                       std::vector<uint32_t>& predictors) {
  thread_local std::vector<uint32_t> first;
  grow_scratch(predictors, 3 * size_t(V));
  return for_each_prediction(
      indices, first_vertex, V, first, [&](uint32_t v, uint32_t o1, uint32_t o2, uint32_t o) {
        parallelogram_form(V, o1, o2, o);
        predictors[3 * size_t(v)] = o1, predictors[3 * size_t(v) + 1] = o2, predictors[3 * size_t(v) + 2] = o;
      });
}

// The layout's tail is the extra bytes.
PredictiveNode parse(std::span<const uint8_t> bytes, const std::string& where) {
  PredictiveNode p = PredictiveNode::parse(bytes, kFormat, kAllFlags, where);
  if (p.tail.size() != p.extra_size) throw Error(where + ": stream sizes do not add up to the node size");
  return p;
}

}  // namespace

PredictiveCodec::PredictiveCodec() {
  meshopt_encodeIndexVersion(1);
}

std::vector<uint8_t> PredictiveCodec::encode(const NodeGeometry& g, const PositionGrid& grid) const {
  if (g.cluster_triangles.size() > 1) throw Error("node codec 2: one cluster per node");
  const QuantizedNode n = quantize_node(g, grid);
  const Mesh& m = *g.mesh;
  const uint32_t V = uint32_t(m.positions.size());
  const uint32_t k = g.position_shift;
  const uint32_t flags = attribute_flags(g);

  // The triangles as the decoder will see them (the index codec may rotate them).
  std::vector<uint8_t> index_stream(meshopt_encodeIndexBufferBound(n.indices.size(), n.index_end));
  index_stream.resize(meshopt_encodeIndexBuffer(index_stream.data(), index_stream.size(), n.indices.data(),
                                                n.indices.size()));
  std::vector<uint32_t> seen(n.indices.size());
  if (meshopt_decodeIndexBuffer(seen.data(), seen.size(), sizeof(uint32_t), index_stream.data(),
                                index_stream.size()) != 0)
    throw Error("node codec: index codec round trip failed");

  std::vector<uint32_t> predictors;
  predictors_of(seen, g.first_vertex, V, predictors);
  const std::vector<uint8_t> locked_stream = encode_locked_stream(n, k);
  return write_predictive_node(NodeHeader::of(kFormat, flags, g, n),
                               predictive_residuals(g, n, predictors, {}, nullptr, seen, locked_stream, grid),
                               encode_attribute_stream(flags, g, n), locked_stream, index_stream, g.extra);
}

DecodedNode PredictiveCodec::decode(std::span<const uint8_t> bytes, const PositionGrid& grid,
                                    const std::string& where) const {
  DecodedNode out;
  decode_into(bytes, grid, where, out);
  return out;
}

void PredictiveCodec::decode_into(std::span<const uint8_t> bytes, const PositionGrid& grid,
                                  const std::string& where, DecodedNode& out) const {
  const PredictiveNode p = parse(bytes, where);
  const uint32_t V = p.vertices;
  const size_t T = p.triangles;
  out.first_vertex = p.first_vertex;
  out.index_end = p.index_end;
  out.extra.assign(p.tail.begin(), p.tail.end());
  out.cluster_triangles.clear();
  Mesh& m = out.mesh;
  m.material = 0;
  m.indices.resize(3 * T);  // zero-fills only beyond the size it had
  if (meshopt_decodeIndexBuffer(m.indices.data(), m.indices.size(), sizeof(uint32_t), p.connectivity.data(),
                                p.connectivity.size()) != 0)
    throw Error(where + ": corrupted index stream");
  thread_local std::vector<uint32_t> predictors;
  const uint32_t max_index = predictors_of(m.indices, p.first_vertex, V, predictors);
  if (T > 0 && max_index >= p.index_end)
    throw Error(where + ": index " + std::to_string(max_index) + " out of range");
  decode_predicted_vertices(p, predictors, nullptr, grid, out, where);
}

NodeSizeBreakdown PredictiveCodec::layout(std::span<const uint8_t> bytes, size_t node_size,
                                          const std::string& where) const {
  uint64_t tail = 0;  // a progressive step's chains (connectivity): the extra bytes
  const NodeSizeBreakdown b = PredictiveNode::layout(bytes, node_size, kFormat, kAllFlags, where, &tail);
  ByteReader r(bytes, where);
  if (tail != NodeHeader::read(r, kFormat, kAllFlags, node_size).extra_size)
    throw Error(where + ": stream sizes do not add up to the node size");
  return b;
}

}  // namespace lodstream::package
