// Decoding coarse coordinates to positions (package/coarse_positions.hpp): the four-vertex step gives the
// scalar formula's bits, with and without a position shift and locked vertices, and coordinates beyond 32
// bits fall back to the formula.
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

TEST(CoarsePositions, ShiftedNodesWithLockedVerticesDecodeAsTheFormula) {
  // Shifts k up to the format's 24 (z's low bits in one window with x's and y's up to k = 19, in a second
  // above), every share of locked vertices, vertex counts around the four-vertex steps, coordinates that
  // fit the 32-bit conversion and some that do not: each vertex decodes to origin + float(q) * step, q the
  // finest-grid coordinate of a locked vertex (its low bits from the locked stream) and c * 2^k of a free
  // one.
  std::mt19937 rng(11);
  PositionGrid grid;
  grid.origin = {-2.5f, 0.75f, 40.0f}, grid.step = 3.1e-5f;
  for (uint32_t k : {1u, 3u, 8u, 19u, 20u, 24u})
    for (double share : {0.0, 0.3, 0.8, 1.0})
      for (size_t V : {1, 4, 7, 8, 13, 64, 101})
        for (bool beyond : {false, true}) {
          const int64_t reach = (int64_t(1) << 31) >> k;  // c * 2^k within [-2^31, 2^31)
          std::uniform_int_distribution<int64_t> coarse(-reach, reach - 1), low(0, (int64_t(1) << k) - 1);
          std::bernoulli_distribution locks(share);
          QuantizedNode n;
          n.c.resize(3 * V), n.q.resize(3 * V), n.locked.resize(V);
          for (size_t v = 0; v < V; ++v) {
            n.locked[v] = locks(rng);
            for (int a = 0; a < 3; ++a) {
              const int64_t c = coarse(rng);
              n.c[3 * v + a] = c;
              n.q[3 * v + a] = c * (int64_t(1) << k) + (n.locked[v] ? low(rng) : 0);
            }
          }
          if (beyond) n.c[3 * (V - 1)] = int64_t(1) << 32, n.q[3 * (V - 1)] = n.c[3 * (V - 1)] << k;
          const std::vector<uint8_t> stream = encode_locked_stream(n, k);
          std::vector<glm::vec3> p(V);
          decode_positions(n.c, LockedStream::parse(stream, V, k, "test"), grid, p.data());
          EXPECT_EQ(p, by_formula(n.q, grid)) << "k " << k << ", locked share " << share << ", " << V
                                              << " vertices" << (beyond ? ", one beyond 32 bits" : "");
        }
}

}  // namespace
