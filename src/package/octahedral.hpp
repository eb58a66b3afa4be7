// Octahedral unit-vector encoding (Cigolle et al. 2014, "A Survey of Efficient Representations for
// Independent Unit Vectors", JCGT 3(2), the "oct" mapping): project n onto the octahedron |x|+|y|+|z| = 1,
// unfold the lower half (z < 0) onto the outer triangles of the square, keep (x, y) in [-1,1]^2 as signed
// b-bit integers. Hand-written: meshoptimizer 0.18's meshopt_decodeFilterOct decodes to integers in place,
// and the decoder here must produce floats in one pass.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>

namespace lodstream::package {

inline float sign_not_zero(float v) {
  return v >= 0.0f ? 1.0f : -1.0f;
}

// n need not be unit length; a zero (or non-finite) vector encodes as +z. Returns components in
// [-(2^(bits-1)-1), 2^(bits-1)-1].
inline glm::ivec2 oct_encode(glm::vec3 n, int bits) {
  // Selects only (no branch, no short-circuit, the division unconditional), so that a loop of encodes
  // vectorizes: the predictive codecs encode a predicted normal per vertex when decoding.
  const float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  const bool usable = (l1 > 0.0f) & (l1 <= std::numeric_limits<float>::max());  // not zero, NaN or infinite
  const float px = usable ? n.x / l1 : 0.0f, py = usable ? n.y / l1 : 0.0f;     // as before: same codes
  const bool lower = usable & (n.z < 0.0f);
  const float fx = lower ? (1.0f - std::abs(py)) * sign_not_zero(px) : px;
  const float fy = lower ? (1.0f - std::abs(px)) * sign_not_zero(py) : py;
  // Round half away from zero without a libm call.
  const float scale = static_cast<float>((1 << (bits - 1)) - 1);
  const float x = std::min(std::max(fx, -1.0f), 1.0f) * scale,
              y = std::min(std::max(fy, -1.0f), 1.0f) * scale;
  return {static_cast<int>(x + std::copysign(0.5f, x)), static_cast<int>(y + std::copysign(0.5f, y))};
}

// Inverse of oct_encode for any integer pair (garbage in gives some unit vector, never NaN). The fold of the
// lower half is written branch-free: with t = max(-z, 0), x += (x >= 0 ? -t : t) equals (1 - |y|) sign(x).
inline glm::vec3 oct_decode(int x, int y, float inv_scale) {
  float fx = std::min(std::max(static_cast<float>(x) * inv_scale, -1.0f), 1.0f);
  float fy = std::min(std::max(static_cast<float>(y) * inv_scale, -1.0f), 1.0f);
  float fz = 1.0f - std::abs(fx) - std::abs(fy);
  float t = std::max(-fz, 0.0f);
  fx += fx >= 0.0f ? -t : t;
  fy += fy >= 0.0f ? -t : t;
  float inv_length = 1.0f / std::sqrt(fx * fx + fy * fy + fz * fz);
  return {fx * inv_length, fy * inv_length, fz * inv_length};
}

}  // namespace lodstream::package
