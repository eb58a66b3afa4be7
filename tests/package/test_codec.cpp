// The node codec on its own: octahedral normals, empty and oversized nodes, progressive-mesh chunks, wide
// position ranges, and robustness against corrupted node bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/octahedral.hpp"
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

TEST(MeshoptCodec, EmptyNodeRoundTrips) {
  Mesh empty;
  NodeGeometry g;
  g.mesh = &empty;
  const MeshoptCodec codec;
  DecodedNode d = codec.decode(codec.encode(g, PositionGrid{}), PositionGrid{}, "empty");
  EXPECT_EQ(d.mesh.vertex_count(), 0u);
  EXPECT_EQ(d.mesh.triangle_count(), 0u);
}

TEST(MeshoptCodec, RejectsInvalidInput) {
  const MeshoptCodec codec;
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

TEST(MeshoptCodec, ProgressiveChunkKeepsOrderExternalIndicesAndVertexData) {
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
  const MeshoptCodec codec;
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

TEST(MeshoptCodec, WidePositionRangeStaysExact) {
  // 2^20 steps across: more than 16 bits per coordinate.
  Mesh m = sphere(1.0f, 8, 16);
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 20);
  NodeGeometry g;
  g.mesh = &m;
  const MeshoptCodec codec;
  DecodedNode d = codec.decode(codec.encode(g, pg), pg, "wide");
  ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
  // Every decoded vertex lies within one (tiny) step of an original one.
  for (const glm::vec3& p : d.mesh.positions) {
    float nearest = INFINITY;
    for (const glm::vec3& o : m.positions) nearest = std::min(nearest, glm::length(p - o));
    EXPECT_LE(nearest, pg.step);
  }
}

TEST(MeshoptCodec, PositionsDecodeExactlyOnTheGrid) {
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
      const MeshoptCodec codec;
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

TEST(MeshoptCodec, CorruptedNodeBytesGiveErrorsOrValidMeshes) {
  Mesh m = uv_sphere(1.0f, 6, 12);
  std::vector<uint8_t> locked(m.vertex_count());
  for (size_t v = 0; v < locked.size(); v += 3) locked[v] = 1;
  NodeGeometry g;
  g.mesh = &m;
  g.locked = locked;
  g.position_shift = 3;
  const PositionGrid pg = PositionGrid::for_bounds(m.bounds());
  const MeshoptCodec codec;
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
