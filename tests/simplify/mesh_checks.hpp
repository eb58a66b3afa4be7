// Checks shared by the simplify tests: brute-force sampled two-sided distance (independent of src/measure;
// small meshes only) and topology checks at the position level.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <map>
#include <random>
#include <tuple>

#include "core/mesh.hpp"

namespace lodstream::test {

// Distance from p to triangle abc (Ericson, Real-Time Collision Detection, 5.1.5 closest point).
inline float point_triangle_distance(glm::vec3 p, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
  glm::vec3 bp = p - b;
  float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
  float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  glm::vec3 cp = p - c;
  float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
  float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  float denom = 1.0f / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

// max over samples of `from` (vertices, edge midpoints, a barycentric grid per triangle) of the distance to
// `to`. A lower bound of the one-sided Hausdorff distance h(from, to).
inline float sampled_one_sided(const Mesh& from, const Mesh& to, int grid = 4) {
  std::vector<glm::vec3> samples(from.positions);
  for (size_t t = 0; t < from.triangle_count(); ++t) {
    glm::vec3 a = from.positions[from.indices[3 * t]], b = from.positions[from.indices[3 * t + 1]],
              c = from.positions[from.indices[3 * t + 2]];
    for (int i = 0; i <= grid; ++i)
      for (int j = 0; i + j <= grid; ++j) {
        float u = float(i) / grid, v = float(j) / grid;
        samples.push_back(a + u * (b - a) + v * (c - a));
      }
  }
  float worst = 0;
  for (const glm::vec3& p : samples) {
    float best = INFINITY;
    for (size_t t = 0; t < to.triangle_count() && best > worst; ++t)
      best = std::min(best, point_triangle_distance(p, to.positions[to.indices[3 * t]],
                                                    to.positions[to.indices[3 * t + 1]],
                                                    to.positions[to.indices[3 * t + 2]]));
    worst = std::max(worst, best);
  }
  return worst;
}

inline float sampled_hausdorff(const Mesh& a, const Mesh& b) {
  return std::max(sampled_one_sided(a, b), sampled_one_sided(b, a));
}

using Key = std::tuple<float, float, float>;
inline Key key(const glm::vec3& p) {
  return {p.x, p.y, p.z};
}

// Directed edges at the position level: (from, to) -> count.
inline std::map<std::pair<Key, Key>, int> directed_edges(const Mesh& m) {
  std::map<std::pair<Key, Key>, int> e;
  for (size_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k)
      ++e[{key(m.positions[m.indices[3 * t + k]]), key(m.positions[m.indices[3 * t + (k + 1) % 3]])}];
  return e;
}

// Every directed edge at most once (no non-manifold edges, consistent orientation).
inline bool is_edge_manifold(const Mesh& m) {
  for (const auto& [edge, count] : directed_edges(m))
    if (count != 1) return false;
  return true;
}

// Directed edges without their reverse: the boundary (position level).
inline std::vector<std::pair<Key, Key>> boundary_edges(const Mesh& m) {
  auto e = directed_edges(m);
  std::vector<std::pair<Key, Key>> open;
  for (const auto& [edge, count] : e)
    if (!e.count({edge.second, edge.first})) open.push_back(edge);
  return open;
}

// A lumpy sphere: radius modulated by a few random harmonics (curved everywhere, no symmetry).
inline Mesh lumpy(Mesh m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  glm::vec3 f1{u(rng), u(rng), u(rng)}, f2{u(rng), u(rng), u(rng)};
  for (auto& p : m.positions) {
    float s = 1.0f + 0.15f * std::sin(3 * glm::dot(p, f1) + 1) + 0.08f * std::sin(7 * glm::dot(p, f2));
    p *= s;
  }
  compute_smooth_normals(m);
  return m;
}

}  // namespace lodstream::test
