#include <algorithm>
#include <cmath>

#include "package/node_codec.hpp"

namespace lodstream::package {

PositionGrid PositionGrid::for_bounds(const Bounds& bounds, int bits) {
  PositionGrid g;
  float diagonal = bounds.diagonal();
  g.origin = bounds.empty() ? glm::vec3(0.0f) : bounds.min;
  g.step = diagonal > 0.0f ? std::ldexp(diagonal, -bits) : 1.0f;
  return g;
}

namespace {

// Whether the distinct positions of `positions` round to distinct points of `grid` (the codec's rounding):
// sorts (grid point, vertex) pairs and looks for a grid point whose vertices do not all share one position.
// With at most 20 bits per diagonal a grid coordinate fits in 21 bits, so a grid point packs into 63 bits.
// Cost: O(V log V), no hashing (two hash sets over the positions cost 7 % of an elephant_1m bake).
bool separates(const std::vector<glm::vec3>& positions, const PositionGrid& grid) {
  std::vector<std::pair<uint64_t, uint32_t>> cells(positions.size());
  for (size_t v = 0; v < positions.size(); ++v) {
    const glm::dvec3 t = (glm::dvec3(positions[v]) - glm::dvec3(grid.origin)) / double(grid.step);
    uint64_t key = 0;
    for (int a = 0; a < 3; ++a) key = key << 21 | (uint64_t(std::llround(t[a])) & 0x1FFFFF);
    cells[v] = {key, uint32_t(v)};
  }
  std::sort(cells.begin(), cells.end());
  for (size_t i = 1; i < cells.size(); ++i)
    if (cells[i].first == cells[i - 1].first && positions[cells[i].second] != positions[cells[i - 1].second])
      return false;
  return true;
}

}  // namespace

PositionGrid PositionGrid::separating(const Mesh& mesh, int min_bits, int max_bits) {
  const Bounds bounds = mesh.bounds();
  for (int bits = min_bits; bits < max_bits; ++bits) {
    const PositionGrid grid = for_bounds(bounds, bits);
    if (separates(mesh.positions, grid)) return grid;
  }
  return for_bounds(bounds, max_bits);
}

void PositionGrid::snap(Mesh& mesh) const {
  for (glm::vec3& p : mesh.positions)
    for (int a = 0; a < 3; ++a) {
      // The codec's formulas: q = round((p - origin) / step), decoded as origin + q * step (float).
      const double q = std::round((double(p[a]) - double(origin[a])) / double(step));
      p[a] = origin[a] + float(q) * step;
    }
  size_t kept = 0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    const glm::vec3 &pa = mesh.positions[a], &pb = mesh.positions[b], &pc = mesh.positions[c];
    if (pa == pb || pb == pc || pc == pa) continue;
    mesh.indices[kept++] = a, mesh.indices[kept++] = b, mesh.indices[kept++] = c;
  }
  mesh.indices.resize(kept);
}

int PositionGrid::bits(const Bounds& bounds) const {
  const float diagonal = bounds.diagonal();
  return diagonal > 0.0f ? int(std::lround(std::log2(double(diagonal) / double(step)))) : 0;
}

}  // namespace lodstream::package
