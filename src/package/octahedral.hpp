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

namespace lodstream::package {

inline float sign_not_zero(float v) {
  return v >= 0.0f ? 1.0f : -1.0f;
}

// n need not be unit length; a zero vector encodes as +z. Returns components in [-(2^(bits-1)-1),
// 2^(bits-1)-1].
inline glm::ivec2 oct_encode(glm::vec3 n, int bits) {
  float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  glm::vec2 p = l1 > 0.0f ? glm::vec2(n.x, n.y) / l1 : glm::vec2(0.0f);
  if (l1 > 0.0f && n.z < 0.0f) {
    p = glm::vec2((1.0f - std::abs(p.y)) * sign_not_zero(p.x), (1.0f - std::abs(p.x)) * sign_not_zero(p.y));
  }
  float scale = static_cast<float>((1 << (bits - 1)) - 1);
  return {static_cast<int>(std::lround(std::clamp(p.x, -1.0f, 1.0f) * scale)),
          static_cast<int>(std::lround(std::clamp(p.y, -1.0f, 1.0f) * scale))};
}

// Inverse of oct_encode for any integer pair (garbage in gives some unit vector, never NaN).
inline glm::vec3 oct_decode(int x, int y, float inv_scale) {
  glm::vec3 v(static_cast<float>(x) * inv_scale, static_cast<float>(y) * inv_scale, 0.0f);
  v.x = std::clamp(v.x, -1.0f, 1.0f);
  v.y = std::clamp(v.y, -1.0f, 1.0f);
  v.z = 1.0f - std::abs(v.x) - std::abs(v.y);
  if (v.z < 0.0f) {
    float x0 = v.x;
    v.x = (1.0f - std::abs(v.y)) * sign_not_zero(x0);
    v.y = (1.0f - std::abs(x0)) * sign_not_zero(v.y);
  }
  return v * (1.0f / std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
}

}  // namespace lodstream::package
