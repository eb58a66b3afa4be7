// The multi-parallelogram prediction of codec 3 (predictive_node.hpp, kMultiParallelogram; the second
// parallelograms from traversal_connectivity.hpp, Parallelograms): the decoder's traversal finds, for a
// vertex, a second parallelogram across an edge whose two triangles it joins, a pair of real triangles
// sharing that edge with every corner but the vertex decoded before it; the encoder chooses the prediction
// where it saves enough (not on a flat regular grid) and such nodes decode to the quantized positions; a
// flipped flag decodes or throws, never reads outside the node.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/node_header.hpp"
#include "package/predictive_node.hpp"
#include "package/traversal_codec.hpp"
#include "package/traversal_connectivity.hpp"
#include "package_fixture.hpp"
#include "support/shapes.hpp"

namespace lodstream::test {
namespace {

using namespace package;

uint32_t flags_of(std::span<const uint8_t> node) {
  ByteReader r(node, "node");
  return NodeHeader::read(r, node[0], 255, node.size()).flags;
}

TEST(MultiParallelogram, TheTraversalJoinsTrianglesAcrossTheirSharedEdges) {
  const Mesh s = sphere(1.0f, 8, 16);
  const uint32_t V = uint32_t(s.vertex_count()), T = uint32_t(s.triangle_count());
  const TraversalCode code = encode_traversal(s.indices, V);
  std::vector<uint32_t> indices(3 * size_t(T)), predictors(3 * size_t(V));
  Parallelograms extra;
  decode_traversal(code.symbols, code.references, T, V, indices.data(), predictors.data(), "node", {},
                   &extra);
  EXPECT_EQ(indices, code.indices);  // the same triangles with or without the parallelograms
  // Directed edge -> the third corner of its triangle.
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> third;
  for (uint32_t t = 0; t < T; ++t)
    for (int k = 0; k < 3; ++k)
      third[{indices[3 * t + k], indices[3 * t + (k + 1) % 3]}] = indices[3 * t + (k + 2) % 3];
  size_t seconds = 0;
  for (uint32_t q = 0; q < V; ++q) {
    auto check = [&](const uint32_t* p) {
      const uint32_t x = p[0], y = p[1], o = p[2];
      EXPECT_LT(std::max({x, y, o}), q);
      EXPECT_EQ(third.at({x, y}), o);  // (x, y, o) a triangle in its winding
      EXPECT_EQ(third.at({y, x}), q);  // joined to (y, x, q) across x - y
    };
    const uint32_t* second = &extra.corners[3 * size_t(q)];
    if (predictors[3 * q] != predictors[3 * q + 1]) check(&predictors[3 * q]);
    if (extra.found[q]) check(second), ++seconds;
  }
  // A closed mesh: most vertices are reached across several decoded edges.
  EXPECT_GT(seconds, size_t(V) / 2);
  // Without the parallelograms, the encoder's predictors.
  std::vector<uint32_t> plain(3 * size_t(V));
  decode_traversal(code.symbols, code.references, T, V, indices.data(), plain.data(), "node");
  EXPECT_EQ(plain, code.predictors);
}

TEST(MultiParallelogram, ChosenWhereItPaysAndDecodesToTheQuantizedPositions) {
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  // The flat regular grid: the gate's parallelogram is exact, nothing to gain; the UV sphere (curved): a
  // second parallelogram saves more than the threshold.
  std::vector<std::pair<Mesh, bool>> cases = {{grid(12), false}, {uv_sphere(1.0f, 16, 24), true}};
  for (const auto& [m, multi] : cases) {
    const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
    NodeGeometry g;
    g.mesh = &m;
    const std::vector<uint8_t> node = codec.encode(g, pg);
    EXPECT_EQ(bool(flags_of(node) & kMultiParallelogram), multi) << m.vertex_count() << " vertices";
    const DecodedNode d = codec.decode(node, pg, "node");
    ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
    expect_near_input(d.mesh, m, 0.87f * pg.step);
  }
}

TEST(MultiParallelogram, AHostileFlagDecodesOrThrows) {
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  // Each node's flag flipped (the flags byte follows the format byte): the residuals read against the other
  // prediction, or (a node that did without) the parallelograms found for a node that never used them.
  for (const Mesh& m : {grid(12), slid_sphere(2), sphere(1.0f, 8, 16)}) {
    const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
    NodeGeometry g;
    g.mesh = &m;
    std::vector<uint8_t> node = codec.encode(g, pg);
    node[1] ^= kMultiParallelogram;
    try {
      const DecodedNode d = codec.decode(node, pg, "node");
      EXPECT_EQ(d.mesh.vertex_count(), m.vertex_count());
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("node: "), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace lodstream::test
