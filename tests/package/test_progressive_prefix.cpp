// Progressive steps through the node codec (first_vertex, index_end beyond the node, extra bytes = chains)
// and their assembly into prefixes (package/progressive_prefix.hpp), on a hand-made totally ordered mesh: a
// square fanned around its centre 4 (full resolution), with 4 -> 0 and then 3 -> 0 substituted.
//   vertices 0 (0,0) 1 (1,0) 2 (1,1) 3 (0,1) 4 (0.5,0.5); parent[3] = parent[4] = 0
//   triangles by death: (1,2,4) survives; (2,3,4) dies with 3; (0,1,4), (3,0,4) die with 4
//   step 0: vertices 0-2, triangle (1,2,4), chains {4 -> 0}; step 1: vertex 3, (2,3,4); step 2: vertex 4, the
//   other two. The codec tests run on both node codecs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"
#include "package/progressive_prefix.hpp"

using namespace lodstream;
using namespace lodstream::package;

namespace {

using Tri = std::array<uint32_t, 3>;

// Triangles rotated to start at their smallest corner (the codec may rotate them), sorted.
std::vector<Tri> canonical(const Mesh& m) {
  std::vector<Tri> out;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    Tri c{m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

struct Steps {
  std::vector<DecodedNode> decoded;
  std::vector<std::vector<uint8_t>> bytes;
};

Steps encode_fan(const NodeCodec& codec) {
  const glm::vec3 p[5] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5f, 0.5f, 0}};
  const std::vector<std::vector<uint32_t>> vertices = {{0, 1, 2}, {3}, {4}};
  const std::vector<std::vector<uint32_t>> indices = {{1, 2, 4}, {2, 3, 4}, {0, 1, 4, 3, 0, 4}};
  const std::vector<std::vector<std::pair<uint32_t, uint32_t>>> chains = {{{4, 0}}, {}, {}};
  const PositionGrid grid = PositionGrid::for_bounds(Bounds{{0, 0, 0}, {1, 1, 0}});
  Steps s;
  for (size_t k = 0; k < 3; ++k) {
    Mesh m;
    for (uint32_t v : vertices[k]) m.positions.push_back(p[v]);
    m.indices = indices[k];
    const std::vector<uint8_t> extra = encode_chains(chains[k]);
    NodeGeometry g;
    g.mesh = &m;
    g.first_vertex = vertices[k][0];
    g.preserve_order = true;
    g.index_end = 5;
    g.extra = extra;
    s.bytes.push_back(codec.encode(g, grid));
    s.decoded.push_back(codec.decode(s.bytes.back(), grid, "step " + std::to_string(k)));
  }
  return s;
}

Mesh assemble(const Steps& s, std::vector<size_t> which) {
  std::vector<const DecodedNode*> steps;
  for (size_t k : which) steps.push_back(&s.decoded[k]);
  return assemble_prefix(steps, "test");
}

class ProgressivePrefixTest : public ::testing::TestWithParam<uint32_t> {};
INSTANTIATE_TEST_SUITE_P(Codecs, ProgressivePrefixTest,
                         ::testing::Values(MeshoptCodec::kId, PredictiveCodec::kId),
                         [](const auto& info) { return "codec" + std::to_string(info.param); });

}  // namespace

TEST_P(ProgressivePrefixTest, EveryPrefixOfTheFanAssembles) {
  const Steps s = encode_fan(node_codec(GetParam()));
  EXPECT_EQ(s.decoded[0].index_end, 5u);
  EXPECT_EQ(s.decoded[1].first_vertex, 3u);
  const Mesh p0 = assemble(s, {0}), p1 = assemble(s, {0, 1}), p2 = assemble(s, {0, 1, 2});
  EXPECT_EQ(p0.vertex_count(), 3u);
  EXPECT_EQ(canonical(p0), (std::vector<Tri>{{0, 1, 2}}));
  EXPECT_EQ(p1.vertex_count(), 4u);
  EXPECT_EQ(canonical(p1), (std::vector<Tri>{{0, 1, 2}, {0, 2, 3}}));
  EXPECT_EQ(canonical(p2), (std::vector<Tri>{{0, 1, 4}, {0, 4, 3}, {1, 2, 4}, {2, 3, 4}}));
  EXPECT_LE(glm::length(p2.positions[4] - glm::vec3(0.5f, 0.5f, 0.0f)), 1e-4f) << "within the 2^-14 grid";
}

TEST(ProgressivePrefix, ChainsRoundTripAndRejectBadPairs) {
  const std::vector<std::pair<uint32_t, uint32_t>> chains = {{3, 0}, {7, 6}, {1000, 2}};
  EXPECT_EQ(decode_chains(encode_chains(chains), 1001, "chains"), chains);
  EXPECT_THROW(decode_chains(encode_chains(chains), 1000, "chains"), Error) << "a vertex at index_end";
  const std::vector<std::pair<uint32_t, uint32_t>> unsorted = {{7, 6}, {3, 0}}, upward = {{3, 5}};
  EXPECT_THROW(encode_chains(unsorted), Error);
  EXPECT_THROW(encode_chains(upward), Error);
  std::vector<uint8_t> bytes = encode_chains(chains);
  bytes.push_back(0);
  EXPECT_THROW(decode_chains(bytes, 1001, "chains"), Error) << "trailing bytes";
  bytes = encode_chains(chains);
  bytes.pop_back();
  EXPECT_THROW(decode_chains(bytes, 1001, "chains"), Error) << "truncated";
}

TEST(ProgressivePrefix, MalformedPrefixesAreErrors) {
  Steps s = encode_fan(MeshoptCodec());
  EXPECT_THROW(assemble(s, {0, 2}), Error) << "a gap between steps";
  EXPECT_THROW(assemble(s, {1}), Error) << "not starting at step 0";
  s.decoded[0].extra.clear();
  EXPECT_THROW(assemble(s, {0}), Error) << "corner 4 has no chain";
  s = encode_fan(MeshoptCodec());
  s.decoded[1].mesh.indices = {2, 3, 3};
  EXPECT_THROW(assemble(s, {0, 1}), Error) << "a degenerate triangle";
}

TEST_P(ProgressivePrefixTest, CodecRejectsIndicesBeyondIndexEnd) {
  const NodeCodec& codec = node_codec(GetParam());
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices = {0, 1, 9};
  NodeGeometry g;
  g.mesh = &m;
  g.preserve_order = true;
  g.index_end = 9;
  EXPECT_THROW(codec.encode(g, PositionGrid{}), Error);
  g.index_end = 2;  // below the node's own vertices
  EXPECT_THROW(codec.encode(g, PositionGrid{}), Error);
  g.index_end = 10;
  const DecodedNode d = codec.decode(codec.encode(g, PositionGrid{}), PositionGrid{}, "node");
  EXPECT_EQ(d.index_end, 10u);
  EXPECT_EQ(canonical(d.mesh), (std::vector<Tri>{{0, 1, 9}}));
  EXPECT_EQ(d.mesh.positions[1], glm::vec3(1, 0, 0)) << "a corner past the node predicts nothing";
}

TEST_P(ProgressivePrefixTest, TruncatedExtraBytesAreErrors) {
  const NodeCodec& codec = node_codec(GetParam());
  const Steps s = encode_fan(codec);
  const PositionGrid grid = PositionGrid::for_bounds(Bounds{{0, 0, 0}, {1, 1, 0}});
  std::vector<uint8_t> bytes = s.bytes[0];
  bytes.pop_back();
  EXPECT_THROW(codec.decode(bytes, grid, "step 0"), Error);
  const std::vector<std::pair<uint32_t, uint32_t>> chains = {{4, 0}};
  EXPECT_EQ(codec.decode(s.bytes[0], grid, "step 0").extra, encode_chains(chains));
}
