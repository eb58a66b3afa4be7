// The node codecs on their own (every test runs on codecs 1, 2 and 3): octahedral normals, empty and
// oversized nodes, progressive-mesh chunks, wide position ranges, attributes, locked vertices, and robustness
// against corrupted node bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "core/error.hpp"
#include "package/format.hpp"
#include "package/meshopt_codec.hpp"
#include "package/octahedral.hpp"
#include "package/predictive_codec.hpp"
#include "package/traversal_codec.hpp"
#include "support/shapes.hpp"

namespace lodstream::test {
namespace {

using namespace package;

TEST(Octahedral, AngularErrorShrinksWithBits) {
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  for (int bits : {8, 10, 16}) {
    const float inv = 1.0f / float((1 << (bits - 1)) - 1);
    double worst = 0.0;
    for (int i = 0; i < 20000; ++i) {
      glm::vec3 n = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
      glm::ivec2 e = oct_encode(n, bits);
      glm::dvec3 a(oct_decode(e.x, e.y, inv)), b(n);
      worst = std::max(worst, std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)));
    }
    // A cell of the [-1,1]^2 square is 2^(2-bits) wide and the map stretches it by about 2 at most, so
    // rounding to the nearest cell errs by less than 5 * 2^-bits radians.
    EXPECT_LT(worst, std::ldexp(5.0, -bits)) << bits << " bits";
    EXPECT_GT(worst, std::ldexp(0.5, -bits)) << bits << " bits";  // and the precision is really that
  }
  EXPECT_EQ(oct_decode(0, 0, 1.0f / 127), glm::vec3(0, 0, 1));
}

TEST(Octahedral, FourLaneDecodeComputesWhatTheScalarOneDoes) {
  // The predictive codecs decode 4 normals at a time: each lane must be the scalar oct_decode's result
  // (the same operations in the same order), for codes of random directions, the octahedron's folds and
  // rims, and codes beyond the square (hostile residuals, clamped).
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  std::uniform_int_distribution<int> beyond(-(1 << 20), 1 << 20);
  int folded = 0, checked = 0;
  for (int bits : {4, 8, 10, 16}) {
    const float inv = 1.0f / float((1 << (bits - 1)) - 1);
    for (int i = 0; i < 4000; ++i) {
      Int4 ox, oy;
      for (int l = 0; l < 4; ++l) {
        const glm::ivec2 e = oct_encode(glm::vec3(g(rng), g(rng), g(rng)), bits);
        ox[l] = e.x, oy[l] = e.y;
        if (i % 4 == 1) ox[l] = beyond(rng);
        if (i % 4 == 3) oy[l] = ox[l] >= 0 ? (1 << (bits - 1)) - 1 - ox[l] : ox[l] + (1 << (bits - 1)) - 1;
      }
      Float4 nx, ny, nz;
      oct_decode(ox, oy, inv, nx, ny, nz);
      for (int l = 0; l < 4; ++l) {
        const glm::vec3 d = oct_decode(ox[l], oy[l], inv);
        ASSERT_EQ(glm::vec3(nx[l], ny[l], nz[l]), d) << ox[l] << " " << oy[l] << ", " << bits << " bits";
        folded += d.z < 0.0f;
        ++checked;
      }
    }
  }
  EXPECT_GT(folded, checked / 5);  // the lower half's fold was exercised
}

class NodeCodecTest : public ::testing::TestWithParam<uint32_t> {};
INSTANTIATE_TEST_SUITE_P(Codecs, NodeCodecTest,
                         ::testing::Values(MeshoptCodec::kId, PredictiveCodec::kId, TraversalCodec::kId),
                         [](const auto& info) { return "codec" + std::to_string(info.param); });

TEST_P(NodeCodecTest, EmptyNodeRoundTrips) {
  Mesh empty;
  NodeGeometry g;
  g.mesh = &empty;
  const NodeCodec& codec = node_codec(GetParam());
  DecodedNode d = codec.decode(codec.encode(g, PositionGrid{}), PositionGrid{}, "empty");
  EXPECT_EQ(d.mesh.vertex_count(), 0u);
  EXPECT_EQ(d.mesh.triangle_count(), 0u);
}

TEST_P(NodeCodecTest, RejectsInvalidInput) {
  const NodeCodec& codec = node_codec(GetParam());
  Mesh big;
  big.positions.resize(65537);
  NodeGeometry g;
  g.mesh = &big;
  EXPECT_THROW(codec.encode(g, PositionGrid{}), Error);
  Mesh bad = grid(2);
  bad.indices.push_back(999);
  bad.indices.push_back(0);
  bad.indices.push_back(1);
  g.mesh = &bad;
  EXPECT_THROW(codec.encode(g, PositionGrid{}), Error);
  Mesh far = grid(2);
  far.positions[0].x = 1e30f;
  g.mesh = &far;
  EXPECT_THROW(codec.encode(g, PositionGrid::for_bounds(grid(2).bounds())), Error);
}

TEST_P(NodeCodecTest, ProgressiveChunkKeepsOrderExternalIndicesAndVertexData) {
  // A chunk whose vertices are 100.. of its representation and whose triangles also use earlier vertices.
  Mesh m = grid(3);
  const uint32_t first = 100;
  std::vector<uint32_t> data;
  for (uint32_t& i : m.indices) i += first;
  m.indices.insert(m.indices.end(), {3, first, first + 1});  // uses vertex 3 from an earlier chunk
  for (size_t v = 0; v < m.vertex_count(); ++v) data.push_back(uint32_t(v * 7919u));
  NodeGeometry g;
  g.mesh = &m;
  g.first_vertex = first;
  g.vertex_data = data;
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds());
  const NodeCodec& codec = node_codec(GetParam());
  DecodedNode d = codec.decode(codec.encode(g, pg), pg, "chunk");
  EXPECT_EQ(d.first_vertex, first);
  EXPECT_EQ(d.vertex_data, data);
  ASSERT_EQ(d.mesh.indices.size(), m.indices.size());
  for (size_t t = 0; t < m.triangle_count(); ++t) {  // same triangle order; a triangle may be rotated
    std::array<uint32_t, 3> a{m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]};
    std::array<uint32_t, 3> b{d.mesh.indices[3 * t], d.mesh.indices[3 * t + 1], d.mesh.indices[3 * t + 2]};
    std::rotate(a.begin(), std::min_element(a.begin(), a.end()), a.end());
    std::rotate(b.begin(), std::min_element(b.begin(), b.end()), b.end());
    EXPECT_EQ(a, b);
  }
  for (size_t v = 0; v < m.vertex_count(); ++v) {  // same vertex order
    EXPECT_LE(glm::length(d.mesh.positions[v] - m.positions[v]), pg.step);
  }
}

TEST_P(NodeCodecTest, PreserveOrderKeepsVerticesAndTriangles) {
  // preserve_order on a standalone node (first_vertex 0): vertex i decodes as input vertex i and triangle t
  // as input triangle t (possibly rotated), though the input order is far from the codecs' preferred one.
  Mesh m = sphere(1.0f, 7, 9);
  std::reverse(m.positions.begin(), m.positions.end());
  std::reverse(m.normals.begin(), m.normals.end());
  const uint32_t last = uint32_t(m.vertex_count()) - 1;
  for (uint32_t& i : m.indices) i = last - i;
  NodeGeometry g;
  g.mesh = &m;
  g.preserve_order = true;
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds());
  const NodeCodec& codec = node_codec(GetParam());
  const DecodedNode d = codec.decode(codec.encode(g, pg), pg, "ordered");
  ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); ++v)
    EXPECT_LE(glm::length(d.mesh.positions[v] - m.positions[v]), pg.step) << v;
  ASSERT_EQ(d.mesh.indices.size(), m.indices.size());
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    std::array<uint32_t, 3> a{m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]};
    std::array<uint32_t, 3> b{d.mesh.indices[3 * t], d.mesh.indices[3 * t + 1], d.mesh.indices[3 * t + 2]};
    std::rotate(a.begin(), std::min_element(a.begin(), a.end()), a.end());
    std::rotate(b.begin(), std::min_element(b.begin(), b.end()), b.end());
    EXPECT_EQ(a, b) << t;
  }
}

TEST_P(NodeCodecTest, WidePositionRangeStaysExact) {
  // 2^20 steps across: more than 16 bits per coordinate.
  Mesh m = sphere(1.0f, 8, 16);
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 20);
  NodeGeometry g;
  g.mesh = &m;
  const NodeCodec& codec = node_codec(GetParam());
  DecodedNode d = codec.decode(codec.encode(g, pg), pg, "wide");
  ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
  // Every decoded vertex lies within one (tiny) step of an original one.
  for (const glm::vec3& p : d.mesh.positions) {
    float nearest = INFINITY;
    for (const glm::vec3& o : m.positions) nearest = std::min(nearest, glm::length(p - o));
    EXPECT_LE(nearest, pg.step);
  }
}

TEST_P(NodeCodecTest, PositionsDecodeExactlyOnTheGrid) {
  // Every decoded position must be the grid value of an input vertex, bit for bit (free vertices rounded to
  // the node's shift), on a smooth mesh, a noisy one (large deltas between neighbours) and a shifted node.
  Mesh smooth = sphere(1.0f, 10, 12);
  Mesh noisy = smooth;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> jitter(-0.3f, 0.3f);
  for (glm::vec3& p : noisy.positions) p += glm::vec3(jitter(rng), jitter(rng), jitter(rng));
  for (const Mesh* m : {&smooth, &noisy})
    for (uint32_t shift : {0u, 3u}) {
      const PositionGrid pg = PositionGrid::for_bounds(m->bounds(), 14);
      NodeGeometry g;
      g.mesh = m;
      g.position_shift = shift;
      const NodeCodec& codec = node_codec(GetParam());
      const DecodedNode d = codec.decode(codec.encode(g, pg), pg, "grid");
      ASSERT_EQ(d.mesh.vertex_count(), m->vertex_count());
      ASSERT_EQ(d.mesh.triangle_count(), m->triangle_count());
      std::vector<glm::vec3> expected;
      for (const glm::vec3& p : m->positions) {
        glm::vec3 e;
        for (int a = 0; a < 3; ++a) {
          const double q = std::round((double(p[a]) - double(pg.origin[a])) / double(pg.step));
          const double c = shift == 0 ? q : std::floor((q + double(1 << (shift - 1))) / double(1 << shift));
          e[a] = pg.origin[a] + float(int64_t(c) << shift) * pg.step;
        }
        expected.push_back(e);
      }
      for (const glm::vec3& p : d.mesh.positions)
        EXPECT_NE(std::find(expected.begin(), expected.end(), p), expected.end())
            << "decoded position (" << p.x << ", " << p.y << ", " << p.z << ") is no input's grid value";
    }
}

TEST_P(NodeCodecTest, LockedVerticesOnTheCoarseGridStoreNoLowBits) {
  // Every vertex locked at shift 3, half of them on grid points that are multiples of 8 (no low bits): the
  // node is stored as if only the others were locked (coarse_positions.hpp), and all decode exactly.
  Mesh m = uv_sphere(1.0f, 9, 14);
  const uint32_t shift = 3;
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
  std::vector<uint8_t> all(m.vertex_count(), 1), unaligned(m.vertex_count(), 0);
  std::vector<uint32_t> id(m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    id[v] = uint32_t(v);
    for (int a = 0; a < 3; ++a) {
      double q = std::round((double(m.positions[v][a]) - double(pg.origin[a])) / double(pg.step));
      if (v % 2 == 0) q = 8.0 * std::round(q / 8.0);
      m.positions[v][a] = pg.origin[a] + float(q) * pg.step;
      unaligned[v] |= std::fmod(q, 8.0) != 0.0;
    }
  }
  ASSERT_GT(std::count(unaligned.begin(), unaligned.end(), 0), ptrdiff_t(m.vertex_count() / 2 - 1));
  NodeGeometry g;
  g.mesh = &m;
  g.position_shift = shift;
  g.normal_bits = 10;
  g.vertex_data = id;
  const NodeCodec& codec = node_codec(GetParam());
  g.locked = all;
  const std::vector<uint8_t> bytes = codec.encode(g, pg);
  g.locked = unaligned;
  EXPECT_EQ(bytes, codec.encode(g, pg));
  const DecodedNode d = codec.decode(bytes, pg, "locked");
  ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
  for (size_t v = 0; v < d.mesh.vertex_count(); ++v)
    EXPECT_EQ(d.mesh.positions[v], m.positions[d.vertex_data[v]]);
}

TEST_P(NodeCodecTest, AttributesAndLockedVerticesRoundTrip) {
  // A node at shift 3 with every attribute; vertex_data numbers the input vertices, so that each decoded
  // vertex (the codec reorders them) is compared with its own input.
  Mesh m = uv_sphere(1.0f, 9, 14);
  m.colors.resize(m.vertex_count());
  std::vector<uint32_t> id(m.vertex_count());
  std::vector<uint8_t> locked(m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    m.colors[v] = glm::vec4(float(v % 7) / 6.0f, 0.25f, 1.0f, float(v % 3) / 2.0f);
    id[v] = uint32_t(v);
    locked[v] = v % 4 == 0;
  }
  const uint32_t shift = 3, bits = 10;
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
  NodeGeometry g;
  g.mesh = &m;
  g.locked = locked;
  g.position_shift = shift;
  g.normal_bits = bits;
  g.vertex_data = id;
  const NodeCodec& codec = node_codec(GetParam());
  const DecodedNode d = codec.decode(codec.encode(g, pg), pg, "attributes");
  ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
  ASSERT_EQ(d.vertex_data.size(), m.vertex_count());
  const glm::vec2 uv_extent(1.0f);  // uv_sphere spans [0,1]^2
  for (size_t v = 0; v < d.mesh.vertex_count(); ++v) {
    const uint32_t o = d.vertex_data[v];
    ASSERT_LT(o, m.vertex_count());
    const glm::vec3 p = d.mesh.positions[v];
    if (locked[o]) {  // exactly the finest-grid value
      for (int a = 0; a < 3; ++a) {
        const double q = std::round((double(m.positions[o][a]) - double(pg.origin[a])) / double(pg.step));
        EXPECT_EQ(p[a], pg.origin[a] + float(q) * pg.step) << "locked vertex " << o;
      }
    } else {  // within half a finest step plus half a coarse step per axis
      for (int a = 0; a < 3; ++a)
        EXPECT_LE(std::abs(p[a] - m.positions[o][a]), (0.5f + 0.5f * float(1 << shift)) * pg.step * 1.001f);
    }
    const glm::dvec3 a(d.mesh.normals[v]), b(glm::normalize(m.normals[o]));
    EXPECT_LT(std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)), std::ldexp(5.0, -int(bits)));
    EXPECT_NEAR(d.mesh.uvs[v].x, m.uvs[o].x, uv_extent.x / 65535.0f);
    EXPECT_NEAR(d.mesh.uvs[v].y, m.uvs[o].y, uv_extent.y / 65535.0f);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(d.mesh.colors[v][c], m.colors[o][c], 0.5f / 255.0f + 1e-6f);
  }
  // The same triangles with the same winding (each possibly rotated, in another order).
  auto canonical = [](std::array<uint32_t, 3> t) {
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    return t;
  };
  std::vector<std::array<uint32_t, 3>> expected, got;
  for (size_t t = 0; t < m.triangle_count(); ++t)
    expected.push_back(canonical({m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]}));
  for (size_t t = 0; t < d.mesh.triangle_count(); ++t)
    got.push_back(canonical({d.vertex_data[d.mesh.indices[3 * t]], d.vertex_data[d.mesh.indices[3 * t + 1]],
                             d.vertex_data[d.mesh.indices[3 * t + 2]]}));
  std::sort(expected.begin(), expected.end());
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, expected);
}

// Every field of two decoded nodes equal.
void expect_same_node(const DecodedNode& a, const DecodedNode& b) {
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.normals, b.mesh.normals);
  EXPECT_EQ(a.mesh.uvs, b.mesh.uvs);
  EXPECT_EQ(a.mesh.colors, b.mesh.colors);
  EXPECT_EQ(a.mesh.indices, b.mesh.indices);
  EXPECT_EQ(a.mesh.material, b.mesh.material);
  EXPECT_EQ(a.first_vertex, b.first_vertex);
  EXPECT_EQ(a.index_end, b.index_end);
  EXPECT_EQ(a.vertex_data, b.vertex_data);
  EXPECT_EQ(a.extra, b.extra);
  EXPECT_EQ(a.cluster_triangles, b.cluster_triangles);
}

TEST_P(NodeCodecTest, DecodeIntoAReusedNodeEqualsAFreshDecode) {
  // decode_into overwrites every field of a node that held another decode: one with more vertices and
  // triangles and every attribute, then one smaller and without attributes (normals included), then the first
  // again.
  Mesh big = uv_sphere(1.0f, 9, 14);
  big.colors.assign(big.vertex_count(), glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
  std::vector<uint32_t> id(big.vertex_count());
  for (size_t v = 0; v < id.size(); ++v) id[v] = uint32_t(7 * v);
  Mesh small = grid(3);
  small.normals.clear();  // decode_predicted_vertices must clear the normals the big node left
  ASSERT_LT(small.vertex_count(), big.vertex_count());
  ASSERT_TRUE(big.has_normals());
  ASSERT_FALSE(small.has_uvs() || small.has_colors());
  Bounds both = big.bounds();
  both.add(small.bounds());
  const PositionGrid pg = PositionGrid::for_bounds(both, 14);
  const NodeCodec& codec = node_codec(GetParam());
  NodeGeometry g;
  g.mesh = &big, g.vertex_data = id;
  const std::vector<uint8_t> big_bytes = codec.encode(g, pg);
  g = NodeGeometry{};
  g.mesh = &small;
  const std::vector<uint8_t> small_bytes = codec.encode(g, pg);
  DecodedNode reused;
  for (const std::vector<uint8_t>* bytes : {&big_bytes, &small_bytes, &big_bytes}) {
    codec.decode_into(*bytes, pg, "reused", reused);
    expect_same_node(reused, codec.decode(*bytes, pg, "fresh"));
  }
  EXPECT_FALSE(reused.mesh.colors.empty());  // the last decode was the node with attributes
}

TEST(TraversalCodec, DecodeIntoAlternatingRecordsAndOrderedNodesEqualsFreshDecodes) {
  // Codec 3 decodes a node whose order is significant as codec 2 (its ordered format) into the same reused
  // node as its records: a record of two clusters with every attribute, then a progressive step with extra
  // bytes and no attributes, and again, each decode equal to a fresh one.
  Mesh big = uv_sphere(1.0f, 9, 14);
  big.colors.assign(big.vertex_count(), glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
  std::vector<uint32_t> id(big.vertex_count());
  for (size_t v = 0; v < id.size(); ++v) id[v] = uint32_t(5 * v);
  const uint32_t T = uint32_t(big.triangle_count());
  const std::vector<uint32_t> clusters = {T / 3, T - T / 3};
  Mesh step = grid(4);
  step.normals.clear();
  const std::vector<uint8_t> extra = {9, 8, 7};
  Bounds both = big.bounds();
  both.add(step.bounds());
  const PositionGrid pg = PositionGrid::for_bounds(both, 14);
  const TraversalCodec codec;
  NodeGeometry g;
  g.mesh = &big, g.vertex_data = id, g.cluster_triangles = clusters;
  const std::vector<uint8_t> record = codec.encode(g, pg);
  g = NodeGeometry{};
  g.mesh = &step, g.preserve_order = true, g.extra = extra;
  const std::vector<uint8_t> ordered = codec.encode(g, pg);
  ASSERT_NE(record[0], ordered[0]);  // the format byte: a traversal, then codec 2's bytes
  DecodedNode reused;
  for (const std::vector<uint8_t>* bytes : {&record, &ordered, &record, &ordered}) {
    codec.decode_into(*bytes, pg, "reused", reused);
    expect_same_node(reused, codec.decode(*bytes, pg, "fresh"));
  }
  EXPECT_EQ(reused.extra, extra);
  EXPECT_TRUE(reused.cluster_triangles.empty() && reused.mesh.colors.empty() && reused.vertex_data.empty());
}

TEST(PredictiveCodec, SmoothMeshTakesFewerBytesThanCodecOneAfterZstd) {
  // On a smooth sphere, parallelogram-predicted positions and normals predicted from the decoded triangles
  // leave small residuals: after zstd (as the writer stores pages) codec 2 must be clearly smaller.
  Mesh m = sphere(1.0f, 24, 48);
  compute_smooth_normals(m);
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
  NodeGeometry g;
  g.mesh = &m;
  auto stored = [&](uint32_t id) { return zstd_compress(node_codec(id).encode(g, pg), 9).size(); };
  const size_t one = stored(MeshoptCodec::kId), two = stored(PredictiveCodec::kId);
  EXPECT_LT(double(two), 0.8 * double(one)) << "codec 1: " << one << " bytes, codec 2: " << two;
}

TEST_P(NodeCodecTest, TriangleSoupsRoundTripTriangleForTriangle) {
  // Whatever the connectivity (pieces, isolated vertices, degenerate and repeated triangles, edges of three
  // or more triangles, neighbours of opposite winding), the decoded triangles are the input's, each with its
  // winding (as a multiset, corners compared by position: vertex i sits at x = i on the grid).
  std::mt19937 rng(7);
  for (int round = 0; round < 40; ++round) {
    const uint32_t V = 3 + rng() % 40;
    Mesh m;
    for (uint32_t v = 0; v < V; ++v) m.positions.push_back({float(v), float(v % 3), 0.0f});
    const uint32_t T = 1 + rng() % (3 * V);
    if (round % 2) {  // half of them mostly a strip (long manifold runs) with some noise
      for (uint32_t t = 0; t + 2 < V && m.indices.size() < 3 * T; ++t) {
        const uint32_t a = t, b = t + 1, c = t + 2;
        m.indices.insert(m.indices.end(), {a, t % 2 ? c : b, t % 2 ? b : c});
      }
    }
    while (m.indices.size() < 3 * size_t(T))
      m.indices.insert(m.indices.end(), {uint32_t(rng() % V), uint32_t(rng() % V), uint32_t(rng() % V)});
    NodeGeometry g;
    g.mesh = &m;
    const PositionGrid pg{glm::vec3(0.0f), 1.0f};
    const NodeCodec& codec = node_codec(GetParam());
    const DecodedNode d = codec.decode(codec.encode(g, pg), pg, "soup");
    ASSERT_EQ(d.mesh.vertex_count(), V);
    auto triangles = [](const Mesh& mesh, auto id) {
      std::vector<std::array<uint32_t, 3>> out;
      for (size_t t = 0; t < mesh.triangle_count(); ++t) {
        std::array<uint32_t, 3> c, smallest;
        for (int k = 0; k < 3; ++k) c[k] = id(mesh.positions[mesh.indices[3 * t + k]]);
        smallest = c;
        for (int k = 0; k < 2; ++k) {  // the least rotation (corners may repeat)
          std::rotate(c.begin(), c.begin() + 1, c.end());
          smallest = std::min(smallest, c);
        }
        out.push_back(smallest);
      }
      std::sort(out.begin(), out.end());
      return out;
    };
    auto by_x = [](glm::vec3 p) { return uint32_t(std::lround(p.x)); };
    EXPECT_EQ(triangles(d.mesh, by_x), triangles(m, by_x)) << "round " << round;
  }
}

TEST(TraversalCodec, ConnectivityTakesFewerBitsThanCodecTwo) {
  // A closed mesh in one node, irregular as scanned meshes are (a sphere whose quads are split along a
  // random diagonal and whose vertices move at random along their radius, so that zstd finds no repeats in
  // a lattice): the traversal's symbols (about half "new vertex") and references cost about 3 bits per
  // triangle after zstd (half a bit of which is the random diagonals' own information), well under codec 2's
  // index stream (meshoptimizer's index codec); and the whole node is smaller than codec 2's.
  const int segments = 48;
  Mesh m = sphere(1.0f, 24, segments);
  std::mt19937 rng(5);
  for (size_t q = 6 * segments; q + 6 <= m.indices.size(); q += 6) {  // quads (a, b, d), (a, d, c)
    const uint32_t a = m.indices[q], b = m.indices[q + 1], d = m.indices[q + 2], c = m.indices[q + 5];
    if (rng() % 2) std::copy_n(std::array<uint32_t, 6>{a, b, c, b, d, c}.begin(), 6, m.indices.begin() + q);
  }
  std::uniform_real_distribution<float> radius(0.97f, 1.03f);
  for (glm::vec3& p : m.positions) p *= radius(rng);
  compute_smooth_normals(m);
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
  NodeGeometry g;
  g.mesh = &m;
  auto connectivity_bits = [&](uint32_t id) {
    const std::vector<uint8_t> node = node_codec(id).encode(g, pg);
    const NodeSizeBreakdown b = node_codec(id).breakdown(node, "sphere");
    const auto first = node.begin() + std::ptrdiff_t(b.header + b.vertices + b.locked);
    const std::vector<uint8_t> stream(first, first + std::ptrdiff_t(b.indices));
    return 8.0 * double(zstd_compress(stream, 9).size()) / double(m.triangle_count());
  };
  const double two = connectivity_bits(PredictiveCodec::kId), three = connectivity_bits(TraversalCodec::kId);
  EXPECT_LT(three, 3.5) << "codec 3: " << three << " bits per triangle";
  EXPECT_LT(three, 0.7 * two) << "codec 2: " << two << ", codec 3: " << three << " bits per triangle";
  auto stored = [&](uint32_t id) { return zstd_compress(node_codec(id).encode(g, pg), 9).size(); };
  EXPECT_LT(stored(TraversalCodec::kId), stored(PredictiveCodec::kId));
}

TEST(TraversalCodec, HostileSymbolsGiveErrorsOrValidMeshes) {
  // Every byte of the symbol and reference streams replaced by symbols valid or not, many times over: the
  // front's checks give an error or a mesh whose indices are all in range, never a crash (run under ASan).
  Mesh m = uv_sphere(1.0f, 6, 12);
  NodeGeometry g;
  g.mesh = &m;
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds());
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  const std::vector<uint8_t> good = codec.encode(g, pg);
  const NodeSizeBreakdown b = codec.breakdown(good, "node");
  const size_t first = b.header + b.vertices + b.locked;
  ASSERT_EQ(first + b.indices, good.size());
  std::mt19937 rng(3);
  size_t errors = 0, decoded = 0;
  for (int round = 0; round < 2000; ++round) {
    std::vector<uint8_t> bad = good;
    const size_t changes = 1 + rng() % 8;
    for (size_t i = 0; i < changes; ++i) bad[first + rng() % b.indices] = uint8_t(rng() % 8);
    try {
      const DecodedNode d = codec.decode(bad, pg, "hostile");
      for (uint32_t i : d.mesh.indices) ASSERT_LT(i, d.mesh.vertex_count());
      ++decoded;
    } catch (const Error&) {
      ++errors;
    }
  }
  EXPECT_GT(errors, 100u);
  EXPECT_GT(decoded, 0u);
}

TEST_P(NodeCodecTest, CorruptedNodeBytesGiveErrorsOrValidMeshes) {
  Mesh m = uv_sphere(1.0f, 6, 12);
  std::vector<uint8_t> locked(m.vertex_count());
  for (size_t v = 0; v < locked.size(); v += 3) locked[v] = 1;
  NodeGeometry g;
  g.mesh = &m;
  g.locked = locked;
  g.position_shift = 3;
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds());
  const NodeCodec& codec = node_codec(GetParam());
  const std::vector<uint8_t> good = codec.encode(g, pg);
  size_t errors = 0, decoded = 0;
  auto attempt = [&](std::span<const uint8_t> bytes) {
    try {
      DecodedNode d = codec.decode(bytes, pg, "fuzz");
      for (uint32_t i : d.mesh.indices) ASSERT_LT(i, d.first_vertex + d.mesh.vertex_count());
      ++decoded;
    } catch (const Error&) {
      ++errors;
    }
  };
  for (size_t at = 0; at < good.size(); ++at) {
    for (uint8_t flip : {0x01, 0x80, 0xff}) {
      std::vector<uint8_t> bad = good;
      bad[at] ^= flip;
      attempt(bad);
    }
  }
  for (size_t n = 0; n < good.size(); ++n) attempt(std::span(good).first(n));
  EXPECT_GT(errors, good.size());  // every truncation and most header flips are detected
  EXPECT_GT(decoded, 0u);          // flips inside the streams decode to (wrong but valid) meshes
}

}  // namespace
}  // namespace lodstream::test
