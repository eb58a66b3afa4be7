// What every node codec does first (package/quantized_node.hpp): q = round((p - origin) / step) with halves
// away from zero (as std::round; the quantizer rounds inline), and quantize_node in two steps for a codec
// that chooses its own vertex order (order_node, then quantize_positions over the order it sets).
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "package/quantized_node.hpp"

using namespace lodstream;
using namespace lodstream::package;

namespace {

// One triangle per three vertices of `positions`, on a grid of step 1 at the origin (q = round(p)).
NodeGeometry geometry_of(Mesh& mesh, const std::vector<glm::vec3>& positions) {
  mesh.positions = positions;
  mesh.indices.clear();
  for (uint32_t v = 0; v + 2 < positions.size(); v += 3)
    mesh.indices.insert(mesh.indices.end(), {v, v + 1, v + 2});
  NodeGeometry g;
  g.mesh = &mesh;
  g.preserve_order = true;
  return g;
}

TEST(QuantizedNode, RoundsHalvesAwayFromZeroAsStdRound) {
  const PositionGrid grid;  // origin 0, step 1
  // Halves of both signs (small and large), values just below a half and between halves.
  const std::vector<float> xs = {0.5f,        -0.5f,        1.5f,  -1.5f,  2.5f,       -2.5f,
                                 0.49999997f, -0.49999997f, 3.25f, -3.75f, 1048575.5f, -1048575.5f};
  std::vector<glm::vec3> positions;
  for (float x : xs) positions.push_back({x, -x, 0.0f});
  while (positions.size() % 3) positions.push_back(glm::vec3(0.0f));
  Mesh mesh;
  const QuantizedNode n = quantize_node(geometry_of(mesh, positions), grid);
  for (size_t v = 0; v < xs.size(); ++v) {
    EXPECT_EQ(n.q[3 * v], int64_t(std::round(double(xs[v])))) << xs[v];
    EXPECT_EQ(n.q[3 * v + 1], int64_t(std::round(-double(xs[v])))) << xs[v];
  }
  // round(x) of 2^30 + 1/2 leaves the grid's range (|q| <= 2^30); 2^30 itself does not.
  Mesh edge;
  EXPECT_NO_THROW(quantize_node(geometry_of(edge, {{1073741824.0f, 0, 0}, {0, 0, 0}, {0, 1, 0}}), grid));
  EXPECT_THROW(quantize_node(geometry_of(edge, {{1073741952.0f, 0, 0}, {0, 0, 0}, {0, 1, 0}}), grid), Error);
  EXPECT_THROW(quantize_node(geometry_of(edge, {{NAN, 0, 0}, {0, 0, 0}, {0, 1, 0}}), grid), Error);
}

TEST(QuantizedNode, QuantizesTheVerticesOfTheOrderTheCodecSets) {
  const PositionGrid grid;
  Mesh mesh;
  NodeGeometry g =
      geometry_of(mesh, {{1, 2, 3}, {-4, 5, 6}, {7, -8, 9}, {10, 11, -12}, {1, 1, 1}, {2, 2, 2}});
  const std::vector<uint8_t> locked = {0, 1, 0, 1, 0, 0};
  g.locked = locked;
  g.position_shift = 1;
  const QuantizedNode whole = quantize_node(g, grid);
  QuantizedNode n = order_node(g, grid);
  EXPECT_EQ(n.order, whole.order);
  EXPECT_EQ(n.indices, whole.indices);
  n.order = {3, 1, 2};  // a codec's own order, leaving vertices out
  quantize_positions(g, grid, n);
  ASSERT_EQ(n.q.size(), 9u);
  ASSERT_EQ(n.locked.size(), 3u);
  for (size_t v = 0; v < 3; ++v) {
    EXPECT_EQ(n.locked[v], locked[n.order[v]]);
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(n.q[3 * v + a], whole.q[3 * n.order[v] + a]);
      EXPECT_EQ(n.c[3 * v + a], whole.c[3 * n.order[v] + a]);
    }
  }
  // The box of the listed vertices only: x of 10 (floor(10 / 2) = 5, locked), -4 (-2) and 7 (round(3.5) = 4).
  EXPECT_EQ(n.cmin[0], -2);
  EXPECT_EQ(n.cmax[0], 5);
}

}  // namespace
