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

}  // namespace lodstream
