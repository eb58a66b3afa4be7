// Whole-component removal (component_removal.hpp). Hand-written: the fallback is part of the hierarchy.
#include "hierarchy/component_removal.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

#include "hierarchy/position_index.hpp"

namespace lodstream::hierarchy {
namespace {

// Union-find over position ids, with path halving.
uint32_t find_root(std::vector<uint32_t>& parent, uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// max over c in `from` of |c - v|, minimised over v in `to` (e_C of the header); +inf when `to` is empty.
double farthest_to_nearest(const Mesh& mesh, std::span<const uint32_t> from, std::span<const uint32_t> to) {
  double best = std::numeric_limits<double>::infinity();
  for (uint32_t v : to) {
    const glm::dvec3 pv(mesh.positions[v]);
    double worst = 0.0;
    for (uint32_t c : from) {
      worst = std::max(worst, glm::length(glm::dvec3(mesh.positions[c]) - pv));
      if (worst >= best) break;
    }
    best = std::min(best, worst);
  }
  return best;
}

}  // namespace

double remove_components(Mesh& mesh, std::span<const uint8_t> locked, size_t target_triangles) {
  const size_t n = mesh.positions.size(), triangles = mesh.triangle_count();
  if (triangles <= target_triangles) return 0.0;
  // Components: triangles joined through shared positions (seams split vertices, not the surface).
  uint32_t ids = 0;
  const std::vector<uint32_t> id = weld_positions(mesh.positions, ids);
  std::vector<uint32_t> parent(ids);
  std::iota(parent.begin(), parent.end(), 0u);
  for (size_t t = 0; t < triangles; ++t)
    for (int k = 1; k < 3; ++k) {
      const uint32_t a = find_root(parent, id[mesh.indices[3 * t]]);
      const uint32_t b = find_root(parent, id[mesh.indices[3 * t + k]]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<uint32_t> component(n);
  std::vector<uint8_t> has_lock(ids, 0);
  std::vector<size_t> tris(ids, 0);
  for (size_t v = 0; v < n; ++v) {
    component[v] = find_root(parent, id[v]);
    has_lock[component[v]] |= locked[v];
  }
  for (size_t t = 0; t < triangles; ++t) ++tris[component[mesh.indices[3 * t]]];
  std::vector<std::vector<uint32_t>> vertices(ids);  // referenced vertices per component
  std::vector<uint8_t> referenced(n, 0);
  for (uint32_t i : mesh.indices) referenced[i] = 1;
  for (uint32_t v = 0; v < n; ++v)
    if (referenced[v]) vertices[component[v]].push_back(v);
  std::vector<uint32_t> candidates;
  for (uint32_t c = 0; c < ids; ++c)
    if (tris[c] > 0 && !has_lock[c]) candidates.push_back(c);
  if (candidates.empty()) return 0.0;
  // At least one component stays: the largest candidate when nothing is locked.
  if (std::none_of(has_lock.begin(), has_lock.end(), [](uint8_t l) { return l != 0; })) {
    auto largest = std::max_element(candidates.begin(), candidates.end(),
                                    [&](uint32_t a, uint32_t b) { return tris[a] < tris[b]; });
    candidates.erase(largest);
  }
  // Nearest-first: each candidate's distance to everything else decides the order.
  std::vector<std::pair<double, uint32_t>> order;
  for (uint32_t c : candidates) {
    std::vector<uint32_t> others;
    for (uint32_t v = 0; v < n; ++v)
      if (referenced[v] && component[v] != c) others.push_back(v);
    order.push_back({farthest_to_nearest(mesh, vertices[c], others), c});
  }
  std::sort(order.begin(), order.end());
  std::vector<uint8_t> dropped(ids, 0);
  size_t left = triangles;
  for (const auto& [distance, c] : order) {
    if (left <= target_triangles) break;
    dropped[c] = 1, left -= tris[c];
  }
  // The bound against what is kept.
  std::vector<uint32_t> kept;
  for (uint32_t v = 0; v < n; ++v)
    if (referenced[v] && !dropped[component[v]]) kept.push_back(v);
  double bound = 0.0;
  for (uint32_t c = 0; c < ids; ++c)
    if (dropped[c]) bound = std::max(bound, farthest_to_nearest(mesh, vertices[c], kept));
  size_t w = 0;
  for (size_t t = 0; t < triangles; ++t)
    if (!dropped[component[mesh.indices[3 * t]]])
      for (int k = 0; k < 3; ++k) mesh.indices[w++] = mesh.indices[3 * t + k];
  mesh.indices.resize(w);
  return bound;
}

}  // namespace lodstream::hierarchy
