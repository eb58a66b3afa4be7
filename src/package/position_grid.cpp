#include <cmath>
#include <unordered_set>

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

struct PointHash {
  size_t operator()(const glm::i64vec3& q) const {
    return size_t(q.x * 0x9E3779B97F4A7C15ull ^ q.y * 0xC2B2AE3D27D4EB4Full ^ q.z * 0x165667B19E3779F9ull);
  }
};
struct PositionHash {
  size_t operator()(const glm::vec3& p) const {
    return std::hash<float>()(p.x) ^ (std::hash<float>()(p.y) * 31) ^ (std::hash<float>()(p.z) * 131);
  }
};

// Whether the distinct positions `points` round to distinct points of `grid` (the codec's rounding).
bool separates(const std::vector<glm::vec3>& points, const PositionGrid& grid) {
  std::unordered_set<glm::i64vec3, PointHash> seen;
  seen.reserve(points.size());
  for (const glm::vec3& p : points) {
    const glm::dvec3 t = (glm::dvec3(p) - glm::dvec3(grid.origin)) / double(grid.step);
    if (!seen.insert(glm::i64vec3(std::round(t.x), std::round(t.y), std::round(t.z))).second) return false;
  }
  return true;
}

}  // namespace

PositionGrid PositionGrid::separating(const Mesh& mesh, int min_bits, int max_bits) {
  const Bounds bounds = mesh.bounds();
  std::unordered_set<glm::vec3, PositionHash> unique(mesh.positions.begin(), mesh.positions.end());
  const std::vector<glm::vec3> points(unique.begin(), unique.end());
  for (int bits = min_bits; bits < max_bits; ++bits) {
    const PositionGrid grid = for_bounds(bounds, bits);
    if (separates(points, grid)) return grid;
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
