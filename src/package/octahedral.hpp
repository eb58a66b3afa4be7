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
// [-scale, scale], rounded: trunc(x + sign(x) round_offset), so 0.5 rounds to the nearest code and a smaller
// offset rounds toward zero with a dead zone (|x| < 1 - round_offset gives 0; the error stays below
// 1 - round_offset code steps); oct_decode with inv_scale = 1 / scale inverts it.
inline glm::ivec2 oct_encode(glm::vec3 n, float scale, float round_offset = 0.5f) {
  // Selects only (no branch, no short-circuit, the division unconditional), so that a loop of encodes
  // vectorizes.
  const float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  const bool usable = (l1 > 0.0f) & (l1 <= std::numeric_limits<float>::max());  // not zero, NaN or infinite
  const float px = usable ? n.x / l1 : 0.0f, py = usable ? n.y / l1 : 0.0f;     // as before: same codes
  const bool lower = usable & (n.z < 0.0f);
  const float fx = lower ? (1.0f - std::abs(py)) * sign_not_zero(px) : px;
  const float fy = lower ? (1.0f - std::abs(px)) * sign_not_zero(py) : py;
  // Round (half away from zero at offset 0.5) without a libm call.
  const float x = std::min(std::max(fx, -1.0f), 1.0f) * scale,
              y = std::min(std::max(fy, -1.0f), 1.0f) * scale;
  return {static_cast<int>(x + std::copysign(round_offset, x)),
          static_cast<int>(y + std::copysign(round_offset, y))};
}

// The b-bit code: components in [-(2^(bits-1)-1), 2^(bits-1)-1].
inline glm::ivec2 oct_encode(glm::vec3 n, int bits) {
  return oct_encode(n, static_cast<float>((1 << (bits - 1)) - 1));
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

// Four lanes (GCC / Clang vector extensions, one SSE register). The 4-, 8- and 16-lane oct_decode below
// computes in each lane exactly what the scalar one computes (the same operations in the same order).
using Float4 = float __attribute__((vector_size(16)));
using Int4 = int32_t __attribute__((vector_size(16)));
// Eight lanes: decode_predicted_normals' AVX2 build takes 8 vertices a step (one AVX register).
using Float8 = float __attribute__((vector_size(32)));
using Int8 = int32_t __attribute__((vector_size(32)));
// Sixteen lanes: decode_predicted_normals' AVX-512 build takes 16 vertices a step (one AVX-512 register).
using Float16 = float __attribute__((vector_size(64)));
using Int16 = int32_t __attribute__((vector_size(64)));

// Lane i of the result is lane I[i] of the concatenation (a, b).
template <int... I>
inline Float4 shuffle(Float4 a, Float4 b) {
#if defined(__clang__)
  return __builtin_shufflevector(a, b, I...);
#else
  return __builtin_shuffle(a, b, Int4{I...});
#endif
}
// Every lane v, in any of the vector types above. Forced inline: a Float8 or Float16 returned out of line
// draws GCC's ABI warning (-Wpsabi) where the caller is not built for AVX or AVX-512.
template <class V>
[[gnu::always_inline]] inline V splat_as(float v) {
  V r;
  for (size_t i = 0; i < sizeof(V) / sizeof(float); ++i) r[i] = v;
  return r;
}
// The lanes and masks below for Float4 / Int4, Float8 / Int8 and Float16 / Int16 alike (M the mask type of
// V).
template <class M, class V>
inline V select(M mask, V yes, V no) {
  return V((M(yes) & mask) | (M(no) & ~mask));
}
template <class V>
inline V abs(V v) {
  using M = decltype(v < v);
  return V(M(v) & 0x7fffffff);
}
// std::max(v, lo) and std::min(v, hi) as the standard defines them ((a < b) ? b : a, (b < a) ? b : a).
template <class V>
inline V clamp(V v, V lo, V hi) {
  const V m = select(v < lo, lo, v);
  return select(hi < m, hi, m);
}
inline Float4 sqrt(Float4 v) {
#if defined(__SSE__)
  return __builtin_ia32_sqrtps(v);
#else
  return Float4{std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2]), std::sqrt(v[3])};
#endif
}
// Float8 and Float16 lane by lane (a template, instantiated only where they are used: a function of Float8
// values draws GCC's ABI note, -Wpsabi, in a translation unit built without AVX). With -fno-math-errno
// (predicted_normals.cpp, the one user) GCC makes it one vsqrtps of all lanes in an AVX2 (8) or AVX-512 (16)
// build; as two Float4 sqrts, the AVX2 build split and joined the lanes around two 4-lane ones (`bench decode
// --runs 1` under callgrind, decode_predicted_normals: refined_elephant 2.46 -> 2.11 M, elephant_1m 39.3
// -> 33.6 M). The same bits: sqrt is correctly rounded whatever the width.
template <class V>
requires(sizeof(V) > sizeof(Float4)) inline V sqrt(V v) {
  V r;
  for (size_t i = 0; i < sizeof(V) / sizeof(float); ++i) r[i] = __builtin_sqrtf(v[i]);
  return r;
}

// oct_decode of 4, 8 or 16 codes (x[i], y[i]: Int4, Int8 or Int16) into (nx[i], ny[i], nz[i]).
template <class I, class V>
inline void oct_decode(I x, I y, float inv_scale, V& nx, V& ny, V& nz) {
  const V zero = splat_as<V>(0.0f), one = splat_as<V>(1.0f);
  V fx = clamp(__builtin_convertvector(x, V) * inv_scale, -one, one);
  V fy = clamp(__builtin_convertvector(y, V) * inv_scale, -one, one);
  const V fz = one - abs(fx) - abs(fy);
  const V t = select(-fz < zero, zero, -fz);
  fx += select(fx >= zero, -t, t);
  fy += select(fy >= zero, -t, t);
  const V inv_length = one / sqrt(fx * fx + fy * fy + fz * fz);
  nx = fx * inv_length, ny = fy * inv_length, nz = fz * inv_length;
}

}  // namespace lodstream::package
