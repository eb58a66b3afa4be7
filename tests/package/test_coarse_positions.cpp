// Decoding coarse coordinates to positions (package/coarse_positions.hpp): the four-vertex step gives the
// scalar formula's bits, and coordinates beyond 32 bits fall back to the formula.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "package/coarse_positions.hpp"

using namespace lodstream;
using namespace lodstream::package;

namespace {

// positions[v] = origin + float(c) * step, axis by axis, as coarse_positions.hpp defines them.
std::vector<glm::vec3> by_formula(const std::vector<int64_t>& c, const PositionGrid& grid) {
  std::vector<glm::vec3> p(c.size() / 3);
  for (size_t v = 0; v < p.size(); ++v)
    for (int a = 0; a < 3; ++a) p[v][a] = grid.origin[a] + static_cast<float>(c[3 * v + a]) * grid.step;
  return p;
}

std::vector<glm::vec3> decoded(const std::vector<int64_t>& c, const PositionGrid& grid) {
  std::vector<glm::vec3> p(c.size() / 3);
  decode_positions(c, LockedStream{{}, p.size(), 0}, grid, p.data());
  return p;
}

TEST(CoarsePositions, EveryVertexCountDecodesAsTheFormula) {
  // Coordinates over the whole 32-bit range (its ends included, and values past 2^24 that float rounds),
  // vertex counts around the four-vertex steps.
  std::mt19937 rng(3);
  std::uniform_int_distribution<int64_t> any(INT32_MIN, INT32_MAX), small(-70000, 70000);
  PositionGrid grid;
  grid.origin = {0.1f, -3.7f, 12.5f}, grid.step = 1.3e-4f;
  for (size_t V : {0, 1, 3, 4, 5, 7, 8, 9, 13, 64, 101}) {
    std::vector<int64_t> c(3 * V);
    for (size_t i = 0; i < c.size(); ++i) c[i] = i % 2 ? small(rng) : any(rng);
    if (V >= 2) c[0] = INT32_MIN, c[4] = INT32_MAX, c[5] = (int64_t(1) << 24) + 1;
    EXPECT_EQ(decoded(c, grid), by_formula(c, grid)) << V << " vertices";
  }
}

TEST(CoarsePositions, CoordinatesBeyondThirtyTwoBitsDecodeAsTheFormula) {
  // A coordinate outside [-2^31, 2^31) (hostile residuals reach ±2^32) does not fit the four-vertex step's
  // 32-bit conversion: every vertex is then decoded by the formula.
  PositionGrid grid;
  grid.origin = {1.0f, 2.0f, 3.0f}, grid.step = 0.5f;
  for (int64_t far :
       {int64_t(1) << 31, -(int64_t(1) << 31) - 1, (int64_t(1) << 32) - 3, -(int64_t(1) << 32)}) {
    for (size_t at : {size_t(0), size_t(13), size_t(23)}) {
      std::vector<int64_t> c(3 * 9, 5);
      c[at] = far;
      EXPECT_EQ(decoded(c, grid), by_formula(c, grid)) << far << " at " << at;
    }
  }
}

}  // namespace
