// The damped parallelogram prediction of the predictive codecs (predictive_node.hpp): the encoder picks the
// damping j per node, nodes with any j decode to the quantized positions, and an invalid j is an error.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "package/byte_planes.hpp"
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

// The traversal codec's node of an irregular grid, and the position grid it is quantized to.
struct TraversalNode {
  PositionGrid pg;
  std::vector<uint8_t> bytes;
};
TraversalNode traversal_node() {
  const Mesh m = jittered_grid(8, 3);
  NodeGeometry g;
  g.mesh = &m;
  TraversalNode n{PositionGrid::for_bounds(m.bounds(), 14), {}};
  n.bytes = node_codec(TraversalCodec::kId).encode(g, n.pg);
  return n;
}

TEST(DampedParallelogram, AnInvalidDampingIsAnError) {
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  auto [pg, node] = traversal_node();
  ByteReader r(node, "node");
  NodeHeader::read(r, 2, 15 | kPlanePrediction | kMultiParallelogram, node.size());
  const size_t at = r.position();  // the widths byte follows the common header
  ASSERT_EQ(node[at] >> 6, 4 - damping_of(node, 2));
  node[at] |= 3 << 6;  // j = 1
  EXPECT_THROW(codec.decode(node, pg, "node"), Error);
}

// A node rewritten with 5-byte position residuals, all 0 but the last vertex's first component, `last`.
std::vector<uint8_t> with_last_residual(std::span<const uint8_t> node, int64_t last) {
  const PredictiveNode p =
      PredictiveNode::parse(node, 2, 15 | kPlanePrediction | kMultiParallelogram, "node");
  PredictiveResiduals r;
  r.position_bytes = 5, r.normal_bytes = p.normal_bytes, r.damping = p.damping,
  r.smooth_normals = p.smooth_normals;
  r.plane = p.flags & kPlanePrediction, r.multi = p.flags & kMultiParallelogram;
  r.positions.assign(3 * size_t(p.vertices), 0),
      r.normals.assign(p.normal_bytes ? 2 * size_t(p.vertices) : 0, 0);
  r.positions[3 * size_t(p.vertices - 1)] = zigzag(last);
  return write_predictive_node(p, r, p.attribute_stream, p.locked_stream, p.connectivity, p.tail);
}

// The decoder range-checks the predicted coordinates (its pass after the prediction, predictive_node.cpp):
// one beyond +-2^32 on the last vertex, the one no other vertex's prediction reads, is an error.
TEST(DampedParallelogram, APositionOffTheGridsRangeIsAnError) {
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  const auto [pg, node] = traversal_node();
  EXPECT_NO_THROW(codec.decode(with_last_residual(node, 1000), pg, "node"));
  for (int64_t last : {int64_t(1) << 33, -(int64_t(1) << 33)}) {
    try {
      codec.decode(with_last_residual(node, last), pg, "node");
      ADD_FAILURE() << last << " decoded";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("out of the grid's range"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace lodstream::test
