// find_parallelograms (multi_parallelogram.hpp) against a brute-force search over all triangle pairs, and the
// mean's rounding.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "package/multi_parallelogram.hpp"
#include "support/shapes.hpp"

namespace lodstream::test {
namespace {

using namespace package;

using Triple = std::array<uint32_t, 3>;

// Every (x, y, z) for v by the definition, in triangle order: a triangle t = (v, x, y) in any rotation with
// x, y < v, and a triangle before t holding y -> x whose third corner z is below v. O(T^2).
std::vector<Triple> brute_force(std::span<const uint32_t> idx, uint32_t v) {
  std::vector<Triple> out;
  const size_t T = idx.size() / 3;
  for (size_t t = 0; t < T; ++t)
    for (int i = 0; i < 3; ++i) {
      const uint32_t x = idx[3 * t + (i + 1) % 3], y = idx[3 * t + (i + 2) % 3];
      if (idx[3 * t + i] != v || x >= v || y >= v) continue;
      for (size_t s = 0; s < t; ++s)
        for (int k = 0; k < 3; ++k)
          if (idx[3 * s + k] == y && idx[3 * s + (k + 1) % 3] == x && idx[3 * s + (k + 2) % 3] < v)
            out.push_back({x, y, idx[3 * s + (k + 2) % 3]});
    }
  return out;
}

// Each vertex's kept parallelograms, in order.
std::vector<std::vector<Triple>> kept(const Parallelograms& p) {
  std::vector<std::vector<Triple>> out(p.count.size());
  for (size_t v = 0; v < p.count.size(); ++v)
    for (uint32_t i = 0; i < p.count[v]; ++i) {
      const uint16_t* xyz = &p.corners[3 * (kMaxParallelograms * v + i)];
      out[v].push_back({xyz[0], xyz[1], xyz[2]});
    }
  return out;
}

TEST(MultiParallelogram, FindsEveryParallelogramOfAManifoldMesh) {
  for (const Mesh& m : {grid(6), uv_sphere(1.0f, 7, 6)}) {
    const uint32_t V = uint32_t(m.vertex_count());
    Parallelograms p;
    find_parallelograms(m.indices, 0, V, p);
    ASSERT_EQ(p.count.size(), V);
    size_t total = 0, several = 0;
    const std::vector<std::vector<Triple>> all = kept(p);
    for (uint32_t v = 0; v < V; ++v) {
      // Valences are at most 6 here (no half-edge dropped); a vertex keeps its first kMaxParallelograms.
      std::vector<Triple> expected = brute_force(m.indices, v);
      expected.resize(std::min<size_t>(expected.size(), kMaxParallelograms));
      EXPECT_EQ(all[v], expected) << v;
      total += all[v].size(), several += all[v].size() > 1;
    }
    EXPECT_GT(total, V / 2);
    EXPECT_GT(several, 0u);
  }
}

TEST(MultiParallelogram, NumbersFromTheFirstVertexAndSkipsOutsideCorners) {
  const Mesh m = grid(5);
  const uint32_t V = uint32_t(m.vertex_count()), offset = 1000;
  std::vector<uint32_t> shifted(m.indices);
  for (uint32_t& i : shifted) i += offset;
  Parallelograms plain, from;
  find_parallelograms(m.indices, 0, V, plain);
  find_parallelograms(shifted, offset, V, from);
  EXPECT_EQ(kept(plain), kept(from));
  // A triangle with a corner past the node and a degenerate one change nothing.
  shifted.insert(shifted.end(), {offset + 3, offset + V, offset + 4, offset + 2, offset + 2, offset + 7});
  find_parallelograms(shifted, offset, V, from);
  EXPECT_EQ(kept(plain), kept(from));
}

TEST(MultiParallelogram, TheMeanRoundsDownLikeTheDampedParallelogram) {
  // Five vertices with x = y = z: 0, 8, 16, -5, 100.
  std::vector<uint64_t> c;
  for (const int64_t x : {0, 8, 16, -5, 100}) c.insert(c.end(), 3, uint64_t(x));
  auto mean = [&](std::span<const uint16_t> xyz) {
    uint64_t P[3];
    multi_parallelogram(c.data(), xyz.data(), uint32_t(xyz.size() / 3), P);
    EXPECT_EQ(P[1], P[0]);  // the same on every axis
    EXPECT_EQ(P[2], P[0]);
    return int64_t(P[0]);
  };
  const uint16_t one[3] = {1, 2, 0};  // (7 (8 + 16) - 0 + 4) / 8 = 21.5 -> 21
  EXPECT_EQ(mean(one), 21);
  const uint16_t two[6] = {1, 2, 0, 3, 0, 4};  // (168 + (-35 - 600) + 8) / 16 = -459 / 16 -> -29
  EXPECT_EQ(mean(two), -29);
  const uint16_t three[9] = {1, 1, 1, 2, 2,
                             2, 4, 4, 4};  // each is its own corner: (8 + 16 + 100 + 12 / 8) / 3
  EXPECT_EQ(mean(three), 41);
  const uint16_t negative[9] = {3, 3, 3, 3, 3, 3, 0, 0, 3};  // (-40 - 40 + 30 + 12) / 24 = -1.58 -> -2
  EXPECT_EQ(mean(negative), -2);
  const uint16_t four[12] = {3, 3, 3, 3, 3, 3, 3, 3, 3, 4, 4, 4};  // (-15 + 100 + 16 / 8) / 4 = 21.75 -> 21
  EXPECT_EQ(mean(four), 21);
}

}  // namespace
}  // namespace lodstream::test
