#include "hierarchy/cut.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace lodstream::hierarchy {

double screen_error(float error, const Sphere& sphere, const CutView& view) {
  if (std::isinf(error)) return INFINITY;
  const double d =
      std::max(glm::length(glm::dvec3(sphere.center) - view.eye) - double(sphere.radius), view.min_distance);
  return double(error) * view.viewport_height / (2.0 * d * std::tan(0.5 * view.fov_y));
}

bool in_cut(float error, const Sphere& sphere, float parent_error, const Sphere& parent_sphere,
            const CutView& view, double tau) {
  return screen_error(error, sphere, view) <= tau && screen_error(parent_error, parent_sphere, view) > tau;
}

std::vector<uint32_t> SurfaceWelder::weld(const Mesh& mesh) {
  std::vector<uint32_t> ids(mesh.positions.size());
  for (size_t v = 0; v < ids.size(); ++v) {
    ids[v] = index_.insert(mesh.positions[v]);
    if (ids[v] == positions_.size()) positions_.push_back(mesh.positions[v]);
  }
  std::vector<uint32_t> triangles;
  triangles.reserve(mesh.indices.size());
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = ids[mesh.indices[t]], b = ids[mesh.indices[t + 1]], c = ids[mesh.indices[t + 2]];
    if (a != b && b != c && a != c) triangles.insert(triangles.end(), {a, b, c});
  }
  return triangles;
}

std::vector<uint64_t> boundary_edges(std::span<const std::vector<uint32_t>* const> parts) {
  size_t count = 0;
  for (const auto* p : parts) count += p->size();
  std::vector<uint64_t> edges;
  edges.reserve(count);
  for (const auto* p : parts)
    for (size_t t = 0; t + 2 < p->size(); t += 3)
      for (int k = 0; k < 3; ++k) {
        uint32_t a = (*p)[t + k], b = (*p)[t + (k + 1) % 3];
        if (a > b) std::swap(a, b);
        edges.push_back(uint64_t(a) << 32 | b);
      }
  tbb::parallel_sort(edges.begin(), edges.end());
  size_t out = 0;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) edges[out++] = edges[i];
    i = j;
  }
  edges.resize(out);
  return edges;
}

std::string compare_boundaries(const std::vector<uint64_t>& cut, const std::vector<uint64_t>& reference,
                               const SurfaceWelder& welder) {
  auto describe = [&](uint64_t e, const char* where) {
    const glm::vec3 a = welder.position(uint32_t(e >> 32)), b = welder.position(uint32_t(e));
    char text[256];
    std::snprintf(text, sizeof text, "boundary edge (%g,%g,%g)-(%g,%g,%g) %s", a.x, a.y, a.z, b.x, b.y, b.z,
                  where);
    return std::string(text);
  };
  auto c = cut.begin();
  auto r = reference.begin();
  while (c != cut.end() || r != reference.end()) {
    if (r == reference.end() || (c != cut.end() && *c < *r))
      return describe(*c, "is in the cut but not in the full-resolution surface (a crack)");
    if (c == cut.end() || *r < *c)
      return describe(*r, "of the full-resolution surface is not a boundary of the cut (overlap or hole)");
    ++c, ++r;
  }
  return "";
}

}  // namespace lodstream::hierarchy
