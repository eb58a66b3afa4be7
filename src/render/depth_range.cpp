#include "render/depth_range.hpp"

#include <algorithm>
#include <limits>

namespace lodstream::render {

DepthRange depth_range(const Camera& camera, std::span<const Bounds> boxes) {
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  float lo = std::numeric_limits<float>::max();
  float hi = -std::numeric_limits<float>::max();
  for (const Bounds& b : boxes) {
    if (b.empty()) continue;
    for (int corner = 0; corner < 8; ++corner) {
      glm::vec3 p{corner & 1 ? b.max.x : b.min.x, corner & 2 ? b.max.y : b.min.y,
                  corner & 4 ? b.max.z : b.min.z};
      float depth = glm::dot(p - camera.eye, forward);
      lo = std::min(lo, depth);
      hi = std::max(hi, depth);
    }
  }
  if (!(hi > 0.0f)) return {};
  DepthRange range;
  range.far_plane = 1.01f * hi;
  range.near_plane = std::max(0.99f * lo, range.far_plane / kMaxDepthRatio);
  return range;
}

}  // namespace lodstream::render
