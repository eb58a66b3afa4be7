// The floor under carried radii (cluster DAG groups and HLOD proxies, LOD book §7.5): before a mesh is
// simplified from per-vertex radii r_v it already carries against a finer surface
// (simplify::Options::vertex_error), the radii below kRadiusFloor x the largest are raised to it. Raising a
// radius always keeps the invariant. Raw radii blow up in the vertical mapping, which asks r_x >= (gap +
// r_old(p) - rest) / mu_x at a point of a new face: that grows without bound (up to the natural mapping's)
// where a corner of small radius sits beside a large one (mu_x -> 0), and such growth compounds over levels;
// a floor of 1 gives the sum of per-level bounds, 0 the raw radii. Triangles drawn by elephant_1m's 1 px
// cuts (near / mid / far) for 0 / 0.3 / 0.5 / 0.65 / 0.8 / 1: 521k/278k/126k, 498k/249k/100k,
// 498k/244k/95k, 503k/244k/95k, 510k/246k/100k, 550k/291k/121k.
#pragma once

#include <algorithm>
#include <vector>

namespace lodstream::hierarchy {

inline constexpr float kRadiusFloor = 0.5f;

// Raises every radius of `radii` to at least kRadiusFloor x the largest. Cost: O(n).
inline void floor_radii(std::vector<float>& radii) {
  if (radii.empty()) return;
  const float floor = kRadiusFloor * *std::max_element(radii.begin(), radii.end());
  for (float& r : radii) r = std::max(r, floor);
}

}  // namespace lodstream::hierarchy
