// The traversal connectivity (package/traversal_connectivity.hpp) on its own: every symbol kind decodes back
// to the encoder's triangles and predictors, and each kind of corrupted stream is refused for its own reason
// (the decoder checks them all in one branch and finds the reason on the way out).
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "core/error.hpp"
#include "package/traversal_connectivity.hpp"
#include "support/shapes.hpp"

namespace lodstream::test {
namespace {

using namespace package;

// Grid triangles with holes punched at random and the rest shuffled: borders (kBoundary), closed loops
// (kEnd) and vertices met again from elsewhere in the front (kSplit), several pieces.
std::vector<uint32_t> holed_grid(int n, uint32_t seed) {
  const Mesh g = grid(n);
  std::mt19937 rng(seed);
  std::vector<std::array<uint32_t, 3>> kept;
  for (size_t t = 0; t < g.triangle_count(); ++t)
    if (rng() % 5 != 0) kept.push_back({g.indices[3 * t], g.indices[3 * t + 1], g.indices[3 * t + 2]});
  std::shuffle(kept.begin(), kept.end(), rng);
  std::vector<uint32_t> out;
  for (const auto& t : kept) out.insert(out.end(), t.begin(), t.end());
  return out;
}

TEST(TraversalConnectivity, EverySymbolKindDecodesToTheEncodersTriangles) {
  std::set<uint32_t> kinds;
  auto round_trip = [&](const std::vector<uint32_t>& indices, uint32_t V) {
    const uint32_t T = uint32_t(indices.size() / 3);
    const TraversalCode code = encode_traversal(indices, V);
    for (uint8_t s : code.symbols) kinds.insert(s & 7);
    std::vector<uint32_t> decoded(3 * size_t(T)), predictors(3 * size_t(V));
    decode_traversal(code.symbols, code.references, T, V, decoded.data(), predictors.data(), "node");
    EXPECT_EQ(decoded, code.indices);
    EXPECT_EQ(predictors, code.predictors);
  };
  const Mesh s = sphere(1.0f, 8, 16);
  round_trip(s.indices, uint32_t(s.vertex_count()));
  for (uint32_t seed = 0; seed < 8; ++seed) round_trip(holed_grid(12, seed), 13 * 13);
  EXPECT_EQ(kinds, (std::set<uint32_t>{kVertex, kLeft, kRight, kBoundary, kSplit, kEnd}));
}

// Ranked symbols: where vertices have about six triangles each (a sphere's rings, a grid), the gate's two
// triangle counts name the kind most of the time, so most symbols are rank 0, where about half were kind
// kVertex (0) and most others kRight or kBoundary.
TEST(TraversalConnectivity, RegularMeshesTakeTheFirstRankMostOfTheTime) {
  for (const Mesh& m : {sphere(1.0f, 16, 32), grid(24)}) {
    const TraversalCode code = encode_traversal(m.indices, uint32_t(m.vertex_count()));
    size_t first = 0;
    for (uint8_t s : code.symbols) first += (s & 7) == 0;
    EXPECT_GT(double(first) / code.symbols.size(), 0.85) << first << " of " << code.symbols.size();
  }
}

TEST(TraversalConnectivity, EachCorruptionIsRefusedForItsReason) {
  // A first triangle of three new vertices (references 0 0 0), then the symbols given.
  auto reason = [](std::vector<uint8_t> symbols, uint32_t T, uint32_t V,
                   std::vector<uint8_t> refs = {0, 0, 0},
                   std::vector<uint32_t> clusters = {}) -> std::string {
    std::vector<uint32_t> indices(3 * size_t(T)), predictors(3 * size_t(V));
    try {
      decode_traversal(symbols, refs, T, V, indices.data(), predictors.data(), "node 3", clusters);
    } catch (const Error& e) {
      return e.what();
    }
    return "decoded";
  };
  auto corrupted = [](const char* why) {
    return std::string("node 3: corrupted connectivity (") + why + ")";
  };
  // The stored byte of `kind` at a gate whose vertices lie in a and b decoded triangles (ranked symbols): the
  // first gate (0 -> 1 of the first triangle) lies in 1 and 1.
  auto at = [](TraversalSymbol kind, uint32_t a = 1, uint32_t b = 1) { return traversal_rank(kind, a, b); };
  EXPECT_EQ(reason({}, 1, 3), "decoded");
  EXPECT_EQ(reason({at(kVertex)}, 2, 4), "decoded");
  EXPECT_EQ(reason({}, 2, 4), corrupted("symbols end early"));
  EXPECT_EQ(reason({at(kBoundary)}, 2, 4), corrupted("symbols end early"));
  EXPECT_EQ(reason({at(kVertex)}, 1, 4), corrupted("symbols left over"));
  EXPECT_EQ(reason({6}, 2, 4), corrupted("unknown symbol"));
  EXPECT_EQ(reason({7}, 2, 4), corrupted("unknown symbol"));
  EXPECT_EQ(reason({at(kVertex)}, 2, 3), corrupted("more vertices than the node holds"));
  EXPECT_EQ(reason({uint8_t(at(kVertex) | 2 << 3)}, 2, 4), corrupted("cluster out of range"));
  // kLeft leaves a loop of 2 (the first triangle's second edge and the new one): no turn there. Its next
  // gate, 1 -> 2, lies in 2 and 2 triangles; after a kVertex in 2 and 1.
  EXPECT_EQ(reason({at(kLeft)}, 2, 3), "decoded");
  EXPECT_EQ(reason({at(kLeft), at(kLeft, 2, 2)}, 3, 3), corrupted("left turn in a loop of 2"));
  EXPECT_EQ(reason({at(kLeft), at(kRight, 2, 2)}, 3, 3), corrupted("right turn in a loop of 2"));
  EXPECT_EQ(reason({at(kLeft), at(kEnd, 2, 2)}, 3, 3), corrupted("end of a loop that is not 3 edges"));
  EXPECT_EQ(reason({at(kVertex), at(kEnd, 2, 1)}, 3, 4), corrupted("end of a loop that is not 3 edges"));
  EXPECT_EQ(reason({at(kEnd)}, 2, 3), "decoded");
  EXPECT_EQ(reason({at(kSplit)}, 2, 4, {0, 0, 0, 2}), "decoded");
  EXPECT_EQ(reason({at(kSplit)}, 2, 4, {0, 0, 0, 3}), corrupted("reference to a vertex not decoded yet"));
  EXPECT_EQ(reason({at(kVertex)}, 2, 4, {0, 0, 0, 0}), corrupted("references left over"));
  // Two clusters of one triangle each: the second triangle tagged with cluster 1 (code 2), or left in the
  // gate's cluster 0, which is then full.
  EXPECT_EQ(reason({uint8_t(at(kVertex) | 2 << 3)}, 2, 4, {0, 0, 0, 0}, {1, 1}), "decoded");
  EXPECT_EQ(reason({at(kVertex)}, 2, 4, {0, 0, 0, 0}, {1, 1}),
            corrupted("triangles per cluster differ from the header's"));
}

}  // namespace
}  // namespace lodstream::test
