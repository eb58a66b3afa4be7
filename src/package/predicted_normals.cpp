#include "package/predicted_normals.hpp"

#include <algorithm>
#include <type_traits>

#include "package/byte_planes.hpp"
#include "package/octahedral.hpp"

namespace lodstream::package {

namespace {

// (v.y, v.z, v.x, v.w): the rotation of a cross product's operands.
NormalSum rotate(NormalSum v) {
  using Lanes = int __attribute__((vector_size(16)));
#if defined(__clang__)
  return __builtin_shufflevector(v, v, 1, 2, 0, 3);
#else
  return __builtin_shuffle(v, Lanes{1, 2, 0, 3});
#endif
}

}  // namespace

void predicted_normals(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t index_end,
                       const glm::vec3* positions, uint32_t V, std::vector<NormalSum>& sum) {
  thread_local std::vector<NormalSum> p;
  p.resize(V);
  for (uint32_t v = 0; v < V; ++v) p[v] = NormalSum{positions[v].x, positions[v].y, positions[v].z, 0.0f};
  sum.assign(V, NormalSum{});
  auto accumulate = [&](auto all_inside) {
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
      const uint32_t a = indices[i] - first_vertex, b = indices[i + 1] - first_vertex,
                     c = indices[i + 2] - first_vertex;
      if (!all_inside && (a >= V || b >= V || c >= V)) continue;
      // cross(e, f) = e.yzx * f.zxy - e.zxy * f.yzx, as glm::cross computes each component.
      const NormalSum e = p[b] - p[a], f = p[c] - p[a];
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
  const size_t V = sum.size();
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

void decode_predicted_normals(std::span<const NormalSum> sum, const uint8_t* planes, uint32_t width,
                              uint32_t bits, glm::vec3* normals) {
  const size_t V = sum.size();
  thread_local std::vector<int32_t> residual;
  residual.resize(2 * V);
  read_planes(planes, V, 2, width, residual.data());
  const float inv_scale = 1.0f / static_cast<float>((1 << (bits - 1)) - 1);
  const int32_t *rx = residual.data(), *ry = rx + V;
  for (size_t v = 0; v < V; ++v) {
    const glm::ivec2 guess = oct_encode(glm::vec3(sum[v][0], sum[v][1], sum[v][2]), int(bits));
    // oct_decode clamps; residuals of a valid node are below 2^17, hostile ones are clamped first.
    normals[v] = oct_decode(guess.x + std::clamp(rx[v], -(1 << 18), 1 << 18),
                            guess.y + std::clamp(ry[v], -(1 << 18), 1 << 18), inv_scale);
  }
}

}  // namespace lodstream::package
