#include "measure/closest_point.hpp"

#include <algorithm>

namespace lodstream {

namespace {
glm::vec3 closest_point_on_segment(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  glm::vec3 ab = b - a;
  float len2 = glm::dot(ab, ab);
  if (len2 <= 0.0f) return a;
  return a + std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) * ab;
}

float distance2(const glm::vec3& p, const glm::vec3& q) {
  glm::vec3 d = p - q;
  return glm::dot(d, d);
}
}  // namespace

glm::vec3 closest_point_on_triangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b,
                                    const glm::vec3& c) {
  // Variable names follow Ericson's listing. The region tests multiply dot products (va, vb, vc are twice a
  // squared area): in float they cancel catastrophically on long thin triangles far from the origin (a 200 m
  // face of buildings.obj measured 0.014 m from itself), so they run in double.
  const glm::dvec3 A(a), ab = glm::dvec3(b) - A, ac = glm::dvec3(c) - A, ap = glm::dvec3(p) - A;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;  // vertex region A

  const glm::dvec3 bp = ap - ab;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;  // vertex region B

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return glm::vec3(A + (d1 / (d1 - d3)) * ab);  // edge region AB

  const glm::dvec3 cp = ap - ac;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;  // vertex region C

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return glm::vec3(A + (d2 / (d2 - d6)) * ac);  // edge region AC

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return glm::vec3(A + ab + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (ac - ab));  // edge region BC

  const double sum = va + vb + vc;  // twice the squared area: zero for a degenerate triangle
  if (sum > 0.0) return glm::vec3(A + ab * (vb / sum) + ac * (vc / sum));  // face region
  // Degenerate triangle (a segment or a point): the nearest of its three edges.
  glm::vec3 best = closest_point_on_segment(p, a, b);
  for (glm::vec3 q : {closest_point_on_segment(p, b, c), closest_point_on_segment(p, c, a)})
    if (distance2(p, q) < distance2(p, best)) best = q;
  return best;
}

}  // namespace lodstream
