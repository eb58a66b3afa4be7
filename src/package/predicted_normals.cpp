#include "package/predicted_normals.hpp"

#include <algorithm>
#include <cstring>
#include <type_traits>

#include "package/byte_planes.hpp"
#include "package/octahedral.hpp"

namespace lodstream::package {

namespace {

// (v.y, v.z, v.x, v.w): the rotation of a cross product's operands.
NormalSum rotate(NormalSum v) {
  return shuffle<1, 2, 0, 3>(v, v);
}

}  // namespace

// target_clones: an AVX2 build of the function besides the baseline one, chosen once at load time (ifunc);
// VEX's 3-operand forms save the register copies that 2-operand SSE needs. Neither build contracts a multiply
// and an add (AVX2 does not include FMA), so both compute the same bits.
__attribute__((target_clones("avx2", "default"))) void predicted_normals(
    std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t index_end, const glm::vec3* positions,
    uint32_t V, std::vector<NormalSum>& sum) {
  // Lanes 0-2 of a 16-byte load at positions[v] are its x y z; lane 3 (the next vertex's x) is never read.
  auto p = [positions](uint32_t v) {
    NormalSum r;
    std::memcpy(&r, &positions[v], sizeof r);
    return r;
  };
  sum.resize((size_t(V) + 3) & ~size_t(3));
  std::memset(sum.data(), 0, sum.size() * sizeof(NormalSum));
  auto accumulate = [&](auto all_inside) {
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
      const uint32_t a = indices[i] - first_vertex, b = indices[i + 1] - first_vertex,
                     c = indices[i + 2] - first_vertex;
      if (!all_inside && (a >= V || b >= V || c >= V)) continue;
      // cross(e, f) = e.yzx * f.zxy - e.zxy * f.yzx, as glm::cross computes each component.
      const NormalSum pa = p(a), e = p(b) - pa, f = p(c) - pa;
      const NormalSum e1 = rotate(e), f1 = rotate(f);
      const NormalSum n = e1 * rotate(f1) - rotate(e1) * f1;
      sum[a] += n, sum[b] += n, sum[c] += n;
    }
  };
  if (first_vertex == 0 && index_end == V)
    accumulate(std::true_type{});
  else
    accumulate(std::false_type{});
}

std::vector<uint64_t> normal_residuals(std::span<const glm::vec3> normals, std::span<const uint32_t> order,
                                       std::span<const NormalSum> sum, uint32_t bits, uint32_t& width) {
  const size_t V = order.size();
  std::vector<uint64_t> residuals(2 * V);
  uint64_t largest = 0;
  for (size_t v = 0; v < V; ++v) {
    const glm::ivec2 truth = oct_encode(normals[order[v]], int(bits));
    const glm::ivec2 guess = oct_encode(glm::vec3(sum[v][0], sum[v][1], sum[v][2]), int(bits));
    for (int a = 0; a < 2; ++a) {
      residuals[2 * v + a] = zigzag(truth[a] - guess[a]);
      largest = std::max(largest, residuals[2 * v + a]);
    }
  }
  width = bytes_for(largest);
  return residuals;
}

// An AVX2 build besides the baseline one, as predicted_normals.
__attribute__((target_clones("avx2", "default"))) void decode_predicted_normals(
    std::span<const NormalSum> sum, uint32_t V, const uint8_t* planes, uint32_t width, uint32_t bits,
    std::vector<glm::vec3>& normals) {
  // Four vertices a step: their sums transposed to lanes, encoded, the residuals added, decoded, transposed
  // back into 12 floats. sum holds a multiple of 4 entries; residual and out take the last step's spare
  // lanes.
  const size_t steps = (size_t(V) + 3) / 4;
  thread_local std::vector<int32_t> residual;
  thread_local std::vector<glm::vec3> out;
  residual.resize(2 * size_t(V) + 4), out.resize(4 * steps);
  read_planes(planes, V, 2, width, residual.data());
  const float inv_scale = 1.0f / static_cast<float>((1 << (bits - 1)) - 1);
  const Int4 limit = {1 << 18, 1 << 18, 1 << 18, 1 << 18};
  auto clamp_residual = [&](const int32_t* r) {
    // residuals of a valid node are below 2^17, hostile ones are clamped first (oct_decode clamps the sum).
    Int4 v;
    std::memcpy(&v, r, sizeof v);
    v = v < -limit ? -limit : v;
    return v > limit ? limit : v;
  };
  for (size_t i = 0; i < steps; ++i) {
    const NormalSum* s = &sum[4 * i];
    const Float4 xy01 = shuffle<0, 4, 1, 5>(s[0], s[1]), xy23 = shuffle<0, 4, 1, 5>(s[2], s[3]);
    const Float4 z01 = shuffle<2, 6, 3, 7>(s[0], s[1]), z23 = shuffle<2, 6, 3, 7>(s[2], s[3]);
    Int4 gx, gy;
    oct_encode(shuffle<0, 1, 4, 5>(xy01, xy23), shuffle<2, 3, 6, 7>(xy01, xy23),
               shuffle<0, 1, 4, 5>(z01, z23), int(bits), gx, gy);
    Float4 x, y, z;
    oct_decode(gx + clamp_residual(&residual[4 * i]), gy + clamp_residual(&residual[V + 4 * i]), inv_scale, x,
               y, z);
    // (x0 y0 z0 x1) (y1 z1 x2 y2) (z2 x3 y3 z3)
    const Float4 xy = shuffle<0, 4, 1, 5>(x, y), yz = shuffle<3, 5, 3, 5>(xy, z),
                 high = shuffle<2, 6, 3, 7>(x, y);
    const Float4 rows[3] = {shuffle<0, 1, 4, 2>(xy, z), shuffle<0, 1, 4, 5>(yz, high),
                            shuffle<6, 2, 3, 7>(high, z)};
    std::memcpy(&out[4 * i], rows, sizeof rows);
  }
  normals.assign(out.begin(), out.begin() + V);
}

}  // namespace lodstream::package
