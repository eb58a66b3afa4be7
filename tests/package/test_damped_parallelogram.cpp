// The damped and multi-parallelogram predictions of the predictive codecs (predictive_node.hpp): the encoder
// picks the predictor per node, and nodes with any of them decode to the quantized positions.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/node_header.hpp"
#include "package/predictive_codec.hpp"
#include "package/predictive_node.hpp"
#include "package/traversal_codec.hpp"
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
  return PredictiveNode::parse(node, format, 15, "node").damping;
}

// The node decodes to m's vertex count, every position a grid point within half a step of some vertex of m
// (the codec reorders).
void expect_quantized_positions(const NodeCodec& codec, std::span<const uint8_t> node, const Mesh& m,
                                const PositionGrid& pg) {
  const DecodedNode d = codec.decode(node, pg, "node");
  ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
  for (const glm::vec3& p : d.mesh.positions) {
    float nearest = INFINITY;
    for (const glm::vec3& q : m.positions) nearest = std::min(nearest, glm::length(p - q));
    EXPECT_LE(nearest, 0.87f * pg.step);
  }
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
    expect_quantized_positions(codec, node, m, pg);
  }
  EXPECT_TRUE(plain);   // the regular grid: the plain parallelogram is exact
  EXPECT_TRUE(damped);  // the jittered grids predict better damped
}

// The widths byte's top bits name the predictor: 0-2 the damping j = 4 - value, 3 the multi-parallelogram.
uint32_t predictor_code(std::span<const uint8_t> node, uint8_t format) {
  ByteReader r(node, "node");
  NodeHeader::read(r, format, 15, node.size());
  return node[r.position()] >> 6;  // the widths byte follows the common header
}

TEST_P(DampedParallelogram, TheMultiParallelogramDecodesToTheQuantizedPositions) {
  const NodeCodec& codec = node_codec(GetParam());
  const uint8_t format = GetParam() == TraversalCodec::kId ? 2 : 1;
  // Strongly jittered grids (a coarse level's irregular sampling): the mean of a vertex's parallelograms
  // predicts better than any single one, so the encoder picks it.
  int multi = 0;
  for (uint32_t seed = 1; seed <= 4; ++seed) {
    const Mesh m = jittered_grid(16, seed);
    const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
    NodeGeometry g;
    g.mesh = &m;
    const std::vector<uint8_t> node = codec.encode(g, pg);
    const bool is_multi = PredictiveNode::parse(node, format, 15, "node").multi;
    EXPECT_EQ(predictor_code(node, format) == 3, is_multi);
    multi += is_multi;
    expect_quantized_positions(codec, node, m, pg);
  }
  EXPECT_GT(multi, 0);
}

// Every predictor code decodes: a node re-labelled with each one decodes to some positions (or a clean
// out-of-range error), never a crash, and only its own code gives back the quantized positions.
TEST(DampedParallelogram, EveryPredictorCodeIsReadAndOnlyTheStoredOneDecodesRight) {
  const Mesh m = jittered_grid(8, 3);
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
  NodeGeometry g;
  g.mesh = &m;
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  const std::vector<uint8_t> node = codec.encode(g, pg);
  const std::vector<glm::vec3> right = codec.decode(node, pg, "node").mesh.positions;
  ByteReader r(node, "node");
  NodeHeader::read(r, 2, 15, node.size());
  const size_t at = r.position();
  const uint32_t stored = predictor_code(node, 2);
  for (uint32_t code = 0; code < 4; ++code) {
    std::vector<uint8_t> relabelled = node;
    relabelled[at] = uint8_t((relabelled[at] & 0x3f) | code << 6);
    try {
      EXPECT_EQ(codec.decode(relabelled, pg, "node").mesh.positions == right, code == stored) << code;
    } catch (const Error&) {
      EXPECT_NE(code, stored);
    }
  }
}

}  // namespace
}  // namespace lodstream::test
