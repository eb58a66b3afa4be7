#include "hierarchy/bounding_sphere.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream::hierarchy {
namespace {

// Grows sphere (c, r) minimally so that it contains the sphere (p, pr) (double precision).
void grow(glm::dvec3& c, double& r, const glm::dvec3& p, double pr) {
  const double d = glm::length(p - c);
  if (d + pr <= r) return;
  if (r + d <= pr) {  // the new sphere contains the old one
    c = p, r = pr;
    return;
  }
  const double new_r = 0.5 * (r + d + pr);
  c += (p - c) * ((new_r - r) / d);
  r = new_r;
}

Sphere to_float(const glm::dvec3& c, double r) {
  // Round outward: the float centre is off by at most |c| * 2^-24 per axis.
  const double slack =
      1e-5 * r + 2.0 * std::ldexp(std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z)}), -23);
  return Sphere{glm::vec3(c), float(r + slack)};
}

}  // namespace

Sphere sphere_of_points(std::span<const glm::vec3> points) {
  if (points.empty()) return Sphere{};
  // Ritter: the point farthest from points[0], the point farthest from that, then grow over all points.
  auto farthest = [&](const glm::dvec3& from) {
    size_t best = 0;
    double best_d = -1.0;
    for (size_t i = 0; i < points.size(); ++i) {
      double d = glm::dot(glm::dvec3(points[i]) - from, glm::dvec3(points[i]) - from);
      if (d > best_d) best_d = d, best = i;
    }
    return glm::dvec3(points[best]);
  };
  const glm::dvec3 a = farthest(glm::dvec3(points[0]));
  const glm::dvec3 b = farthest(a);
  glm::dvec3 c = 0.5 * (a + b);
  double r = 0.5 * glm::length(b - a);
  for (const glm::vec3& p : points) grow(c, r, glm::dvec3(p), 0.0);
  return to_float(c, r);
}

Sphere sphere_of_spheres(std::span<const Sphere> spheres, std::span<const glm::vec3> points) {
  if (spheres.empty()) return sphere_of_points(points);
  size_t largest = 0;
  for (size_t i = 1; i < spheres.size(); ++i)
    if (spheres[i].radius > spheres[largest].radius) largest = i;
  glm::dvec3 c(spheres[largest].center);
  double r = spheres[largest].radius;
  for (const Sphere& s : spheres) grow(c, r, glm::dvec3(s.center), s.radius);
  for (const glm::vec3& p : points) grow(c, r, glm::dvec3(p), 0.0);
  return to_float(c, r);
}

}  // namespace lodstream::hierarchy
