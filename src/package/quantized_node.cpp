#include "package/quantized_node.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/error.hpp"

namespace lodstream::package {

QuantizedNode order_node(const NodeGeometry& g, const PositionGrid& grid) {
  if (!g.mesh) throw Error("node codec: no mesh given");
  const Mesh& m = *g.mesh;
  const size_t V = m.positions.size();
  auto invalid = [](const std::string& what) { throw Error("node codec: " + what); };
  if (V > kMaxNodeVertices) invalid(std::to_string(V) + " vertices exceed the 65536 a node may hold");
  if ((m.has_normals() && m.normals.size() != V) || (m.has_uvs() && m.uvs.size() != V) ||
      (m.has_colors() && m.colors.size() != V) || (!g.locked.empty() && g.locked.size() != V) ||
      (!g.vertex_data.empty() && g.vertex_data.size() != V)) {
    invalid("attribute arrays differ in length from positions");
  }
  if (m.indices.size() % 3 != 0) invalid("index count is not a multiple of 3");
  if (g.position_shift > kMaxPositionShift) invalid("position shift above 24");
  if (m.has_normals() && (g.normal_bits < 4 || g.normal_bits > 16)) invalid("normal bits outside 4..16");
  if (!(grid.step > 0.0f) || !std::isfinite(grid.step)) invalid("grid step must be positive and finite");
  const uint64_t vertex_end = uint64_t(g.first_vertex) + V;
  if (vertex_end > UINT32_MAX) invalid("first vertex out of range");
  if (g.index_end != 0 && g.index_end < vertex_end) invalid("index end below the node's last vertex");
  const uint64_t index_end = g.index_end == 0 ? vertex_end : g.index_end;
  for (uint32_t i : m.indices) {
    if (i >= index_end) invalid("index " + std::to_string(i) + " out of range");
  }
  if (g.cluster_triangles.size() > kMaxRecordClusters) invalid("more clusters than a record may hold");
  uint64_t cluster_sum = 0;
  for (uint32_t t : g.cluster_triangles) {
    if (t == 0) invalid("a cluster of no triangles");
    cluster_sum += t;
  }
  if (!g.cluster_triangles.empty() && cluster_sum != m.indices.size() / 3)
    invalid("cluster triangle counts do not add up to the triangles");

  // Vertex order: meshopt's vertex-cache then vertex-fetch order (what its codecs compress best), unless the
  // caller's order is significant. order[new] = old.
  QuantizedNode n;
  n.index_end = static_cast<uint32_t>(index_end);
  n.indices = m.indices;
  n.order.resize(V);
  std::iota(n.order.begin(), n.order.end(), 0u);
  if (g.first_vertex == 0 && !g.preserve_order && V > 0) {
    std::vector<uint32_t> optimized(n.indices.size());
    meshopt_optimizeVertexCache(optimized.data(), n.indices.data(), n.indices.size(), V);
    std::vector<uint32_t> remap(V);
    size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), optimized.data(), optimized.size(), V);
    for (uint32_t& r : remap) {
      if (r == ~0u) r = static_cast<uint32_t>(used++);  // unreferenced vertices keep a place at the end
    }
    for (size_t old = 0; old < V; ++old) n.order[remap[old]] = static_cast<uint32_t>(old);
    for (size_t i = 0; i < n.indices.size(); ++i) n.indices[i] = remap[optimized[i]];
  }
  return n;
}

void quantize_positions(const NodeGeometry& g, const PositionGrid& grid, QuantizedNode& n) {
  const Mesh& m = *g.mesh;
  const size_t V = n.order.size();
  auto invalid = [](const std::string& what) { throw Error("node codec: " + what); };
  // Quantization: q = round((p - origin) / step); c = round(q / 2^k) for free vertices, floor(q / 2^k) for
  // locked ones (whose k low bits the codec stores apart).
  const uint32_t k = g.position_shift;
  // Appended (a resize would zero-fill q and c first).
  n.q.clear(), n.c.clear(), n.locked.clear();
  n.q.reserve(3 * V), n.c.reserve(3 * V), n.locked.reserve(V);
  for (size_t v = 0; v < V; ++v) {
    const uint32_t old = n.order[v];
    const bool locked = !g.locked.empty() && g.locked[old];
    n.locked.push_back(locked);
    for (int a = 0; a < 3; ++a) {
      // round(x) <= kMaxGridCoordinate exactly when |x| < kMaxGridCoordinate + 1/2 (false for NaN).
      const double x = (double(m.positions[old][a]) - double(grid.origin[a])) / double(grid.step);
      if (!(std::abs(x) < double(kMaxGridCoordinate) + 0.5))
        invalid("position outside the range of the grid");
      const int64_t qa = round_half_away(x);
      int64_t ca = (k == 0 || locked) ? (qa >> k) : ((qa + (int64_t(1) << (k - 1))) >> k);
      n.q.push_back(qa);
      n.c.push_back(ca);
      n.cmin[a] = v == 0 ? ca : std::min(n.cmin[a], ca);
      n.cmax[a] = v == 0 ? ca : std::max(n.cmax[a], ca);
    }
  }
  if (m.has_uvs()) {
    glm::vec2 uv_min = V ? m.uvs[0] : glm::vec2(0.0f), uv_max = uv_min;
    for (const glm::vec2& uv : m.uvs) {
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) invalid("non-finite texture coordinate");
      uv_min = glm::min(uv_min, uv);
      uv_max = glm::max(uv_max, uv);
    }
    n.uv_min = uv_min;
    n.uv_extent = uv_max - uv_min;
  }
}

QuantizedNode quantize_node(const NodeGeometry& g, const PositionGrid& grid) {
  QuantizedNode n = order_node(g, grid);
  quantize_positions(g, grid, n);
  return n;
}

}  // namespace lodstream::package
