// Near and far clip planes that enclose what is drawn, as seen from a camera.
#pragma once

#include <span>

#include "core/bounds.hpp"
#include "core/camera.hpp"

namespace lodstream::render {

struct DepthRange {
  float near_plane = 0.0f;
  float far_plane = 0.0f;
  bool empty() const { return !(far_plane > 0.0f); }  // everything lies behind the eye
};

// The depth (distance along the view direction) of every corner of the world-space boxes `boxes`, widened by
// 1 %: far = 1.01 max depth, near = max(0.99 min depth, far / kMaxDepthRatio), so a camera inside the boxes
// still gets a usable near plane and a 24-bit depth buffer keeps about 2^24 / kMaxDepthRatio steps at the far
// plane. empty() when no corner lies in front of the eye. Cost: 8 corners per box.
inline constexpr float kMaxDepthRatio = 2000.0f;
DepthRange depth_range(const Camera& camera, std::span<const Bounds> boxes);

}  // namespace lodstream::render
