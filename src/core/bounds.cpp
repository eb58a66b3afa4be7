#include "core/bounds.hpp"

namespace lodstream {

Bounds transform_bounds(const Bounds& b, const glm::mat4& m) {
  Bounds out;
  if (b.empty()) return out;
  for (int i = 0; i < 8; ++i) {
    glm::vec3 c{(i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z};
    out.add(glm::vec3(m * glm::vec4(c, 1.0f)));
  }
  return out;
}

bool sphere_contains(const Sphere& outer, const Sphere& inner, double tolerance) {
  const double d = glm::length(glm::dvec3(inner.center) - glm::dvec3(outer.center));
  return d + double(inner.radius) <= double(outer.radius) * (1.0 + tolerance) + 1e-30;
}

}  // namespace lodstream
