// Axis-aligned bounding box and bounding sphere. Cost: O(1) per point added.
#pragma once

#include <glm/glm.hpp>
#include <limits>
#include <span>

namespace lodstream {

struct Bounds {
  glm::vec3 min{std::numeric_limits<float>::max()};
  glm::vec3 max{-std::numeric_limits<float>::max()};

  bool empty() const { return min.x > max.x; }
  void add(const glm::vec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void add(const Bounds& b) {
    if (b.empty()) return;
    add(b.min);
    add(b.max);
  }
  glm::vec3 center() const { return (min + max) * 0.5f; }
  glm::vec3 extent() const { return empty() ? glm::vec3(0.0f) : max - min; }
  // Length of the box diagonal; 0 for an empty box. Relative errors in lodstream are fractions of this.
  float diagonal() const { return glm::length(extent()); }

  static Bounds of(std::span<const glm::vec3> points) {
    Bounds b;
    for (const auto& p : points) b.add(p);
    return b;
  }
};

struct Sphere {
  glm::vec3 center{0.0f};
  float radius = 0.0f;
};

// Whether `outer` contains `inner` (centre distance plus inner radius, in double precision), allowing
// `tolerance` x outer's radius of slack; tolerance 0 is exact containment (up to 1e-30 absolute).
bool sphere_contains(const Sphere& outer, const Sphere& inner, double tolerance = 1e-6);

// Bounds of a box under an affine transform (the box of the eight transformed corners).
Bounds transform_bounds(const Bounds& b, const glm::mat4& m);

}  // namespace lodstream
