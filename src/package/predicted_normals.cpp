#include "package/predicted_normals.hpp"

#include <algorithm>
#include <type_traits>

#include "package/byte_planes.hpp"
#include "package/octahedral.hpp"

namespace lodstream::package {

void predicted_normals(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t index_end,
                       const glm::vec3* positions, uint32_t V, std::vector<glm::vec3>& sum) {
  sum.assign(V, glm::vec3(0.0f));
  auto accumulate = [&](auto all_inside) {
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
      const uint32_t a = indices[i] - first_vertex, b = indices[i + 1] - first_vertex,
                     c = indices[i + 2] - first_vertex;
      if (!all_inside && (a >= V || b >= V || c >= V)) continue;
      const glm::vec3 n = glm::cross(positions[b] - positions[a], positions[c] - positions[a]);
      sum[a] += n, sum[b] += n, sum[c] += n;
    }
  };
  if (first_vertex == 0 && index_end == V)
    accumulate(std::true_type{});
  else
    accumulate(std::false_type{});
}

void predicted_codes(std::span<const glm::vec3> sum, uint32_t bits, int32_t* x, int32_t* y) {
  for (size_t v = 0; v < sum.size(); ++v) {
    const glm::ivec2 code = oct_encode(sum[v], int(bits));
    x[v] = code.x, y[v] = code.y;
  }
}

std::vector<uint64_t> normal_residuals(std::span<const glm::vec3> normals, std::span<const uint32_t> order,
                                       std::span<const glm::vec3> sum, uint32_t bits, uint32_t& width) {
  const size_t V = sum.size();
  std::vector<int32_t> guess(2 * V);
  predicted_codes(sum, bits, guess.data(), guess.data() + V);
  std::vector<uint64_t> residuals(2 * V);
  uint64_t largest = 0;
  for (size_t v = 0; v < V; ++v) {
    const glm::ivec2 truth = oct_encode(normals[order[v]], int(bits));
    for (int a = 0; a < 2; ++a) {
      residuals[2 * v + a] = zigzag(truth[a] - guess[a * V + v]);
      largest = std::max(largest, residuals[2 * v + a]);
    }
  }
  width = bytes_for(largest);
  return residuals;
}

void decode_predicted_normals(std::span<const glm::vec3> sum, const uint8_t* planes, uint32_t width,
                              uint32_t bits, glm::vec3* normals) {
  const size_t V = sum.size();
  thread_local std::vector<int32_t> residual, guess;
  residual.resize(2 * V), guess.resize(2 * V);
  read_planes(planes, V, 2, width, residual.data());
  predicted_codes(sum, bits, guess.data(), guess.data() + V);
  const float inv_scale = 1.0f / static_cast<float>((1 << (bits - 1)) - 1);
  const int32_t *rx = residual.data(), *ry = rx + V, *gx = guess.data(), *gy = gx + V;
  for (size_t v = 0; v < V; ++v) {
    // oct_decode clamps; residuals of a valid node are below 2^17, hostile ones are clamped first.
    normals[v] = oct_decode(gx[v] + std::clamp(rx[v], -(1 << 18), 1 << 18),
                            gy[v] + std::clamp(ry[v], -(1 << 18), 1 << 18), inv_scale);
  }
}

}  // namespace lodstream::package
