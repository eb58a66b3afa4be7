// The damped parallelogram prediction of the predictive codecs (predictive_node.hpp): the encoder picks the
// damping j per node, nodes with any j decode to the quantized positions, and an invalid j is an error.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/node_header.hpp"
#include "package/predictive_codec.hpp"
#include "package/predictive_node.hpp"
#include "package/traversal_codec.hpp"
#include "package_fixture.hpp"
#include "support/shapes.hpp"

namespace lodstream::test {
namespace {

using namespace package;

// A flat grid whose vertices are moved by up to a third of an edge: an irregular mesh like a coarse level's.
Mesh jittered_grid(int n, uint32_t seed) {
  Mesh m = grid(n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(-0.33f / float(n), 0.33f / float(n));
  for (glm::vec3& p : m.positions) p += glm::vec3(d(rng), d(rng), 0.2f * d(rng));
  return m;
}

uint32_t damping_of(std::span<const uint8_t> node, uint8_t format) {
  return PredictiveNode::parse(node, format, 15 | kPlanePrediction | kMultiParallelogram, "node").damping;
}

class DampedParallelogram : public ::testing::TestWithParam<uint32_t> {};

INSTANTIATE_TEST_SUITE_P(Codecs, DampedParallelogram,
                         ::testing::Values(PredictiveCodec::kId, TraversalCodec::kId),
                         [](const auto& info) { return "codec" + std::to_string(info.param); });

TEST_P(DampedParallelogram, EveryDampingDecodesToTheQuantizedPositions) {
  const NodeCodec& codec = node_codec(GetParam());
  const uint8_t format = GetParam() == TraversalCodec::kId ? 2 : 1;
  bool damped = false, plain = false;
  for (const Mesh& m : {grid(12), jittered_grid(12, 1), jittered_grid(12, 2), uv_sphere(1.0f, 9, 14)}) {
    const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
    NodeGeometry g;
    g.mesh = &m;
    const std::vector<uint8_t> node = codec.encode(g, pg);
    const uint32_t j = damping_of(node, format);
    EXPECT_GE(j, 2u);
    EXPECT_LE(j, 4u);
    (j < 4 ? damped : plain) = true;
    const DecodedNode d = codec.decode(node, pg, "node");
    ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
    // Every decoded position is a grid point within half a step of some input vertex (the codec reorders).
    expect_near_input(d.mesh, m, 0.87f * pg.step);
  }
  EXPECT_TRUE(plain);   // the regular grid: the plain parallelogram is exact
  EXPECT_TRUE(damped);  // the jittered grids predict better damped
}

TEST(DampedParallelogram, AnInvalidDampingIsAnError) {
  const Mesh m = jittered_grid(8, 3);
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
  NodeGeometry g;
  g.mesh = &m;
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  std::vector<uint8_t> node = codec.encode(g, pg);
  ByteReader r(node, "node");
  NodeHeader::read(r, 2, 15 | kPlanePrediction | kMultiParallelogram, node.size());
  const size_t at = r.position();  // the widths byte follows the common header
  ASSERT_EQ(node[at] >> 6, 4 - damping_of(node, 2));
  node[at] |= 3 << 6;  // j = 1
  EXPECT_THROW(codec.decode(node, pg, "node"), Error);
}

}  // namespace
}  // namespace lodstream::test
