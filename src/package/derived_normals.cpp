#include "package/derived_normals.hpp"

#include <algorithm>

namespace lodstream::package {

namespace {

// The largest zigzagged code within one step of the prediction: +-1 maps to 1 and 2.
constexpr uint64_t kOneStep = 2;

}  // namespace

uint32_t open_vertices(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t V,
                       std::vector<uint8_t>& open) {
  // balance[v]: the sum of next - previous corner over v's triangles (wrapping); open[v] starts as "no
  // triangle" and is cleared by v's first triangle.
  thread_local std::vector<uint32_t> balance;
  balance.assign(V, 0u);
  open.assign(V, 1u);
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    const uint32_t a = indices[i] - first_vertex, b = indices[i + 1] - first_vertex,
                   c = indices[i + 2] - first_vertex;
    if (a >= V || b >= V || c >= V) continue;
    balance[a] += b - c, balance[b] += c - a, balance[c] += a - b;
    open[a] = open[b] = open[c] = 0;
  }
  uint32_t count = 0;
  for (uint32_t v = 0; v < V; ++v) {
    open[v] |= balance[v] != 0;
    count += open[v];
  }
  return count;
}

uint32_t derive_closed_normals(std::span<uint64_t> codes, std::span<const uint8_t> open) {
  uint32_t changed = 0;
  for (size_t v = 0; v < open.size(); ++v) {
    uint64_t* c = &codes[2 * v];
    if (open[v] || (c[0] | c[1]) == 0 || std::max(c[0], c[1]) > kOneStep) continue;
    c[0] = c[1] = 0;
    ++changed;
  }
  return changed;
}

}  // namespace lodstream::package
