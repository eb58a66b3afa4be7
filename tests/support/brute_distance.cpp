#include "support/brute_distance.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream::test {

double point_triangle_distance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const double denom = 1.0 / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

double distance_to(const glm::dvec3& p, const std::vector<const Mesh*>& meshes) {
  double best = INFINITY;
  for (const Mesh* m : meshes)
    for (size_t t = 0; t + 2 < m->indices.size(); t += 3)
      best = std::min(best,
                      point_triangle_distance(p, m->positions[m->indices[t]], m->positions[m->indices[t + 1]],
                                              m->positions[m->indices[t + 2]]));
  return best;
}

std::vector<glm::dvec3> samples(const Mesh& m) {
  std::vector<glm::dvec3> s(m.positions.begin(), m.positions.end());
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    glm::dvec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]],
               c = m.positions[m.indices[t + 2]];
    s.push_back((a + b + c) / 3.0);
    s.push_back((a + b) * 0.5);
  }
  return s;
}

}  // namespace lodstream::test
