// The traversal connectivity (package/traversal_connectivity.hpp) on its own: every symbol kind decodes back
// to the encoder's triangles and predictors, and each kind of corrupted stream is refused for its own reason
// (the decoder checks them all in one branch and finds the reason on the way out).
#include <gtest/gtest.h>

#include <algorithm>
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
    for (const TraversalStep& s : code.steps) kinds.insert(s.symbol_class % 6);
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

// A record of 31 clusters whose triangles lie scattered (shuffled, then cut into 31 ranges): the traversal
// meets the clusters in every order, so that the move-to-front ranks of their codes take every path of
// to_front (ranks below 8, below 16 and up to 30), and the decoder puts every triangle back in its cluster.
TEST(TraversalConnectivity, ScatteredClustersOfEveryRankDecode) {
  const Mesh s = sphere(1.0f, 16, 32);
  const uint32_t T = uint32_t(s.triangle_count()), V = uint32_t(s.vertex_count());
  std::vector<uint32_t> order(T);
  for (uint32_t t = 0; t < T; ++t) order[t] = t;
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  std::vector<uint32_t> indices;
  for (uint32_t t : order)
    indices.insert(indices.end(), &s.indices[3 * size_t(t)], &s.indices[3 * size_t(t) + 3]);
  std::vector<uint32_t> clusters(31, T / 31);
  clusters.back() += T % 31;
  const TraversalCode code = encode_traversal(indices, V, clusters);
  std::set<uint32_t> ranks;
  for (const TraversalStep& step : code.steps)
    if (step.symbol_class >= 6) ranks.insert(step.rank);
  EXPECT_GT(*ranks.rbegin(), 24u);
  EXPECT_GT(std::count_if(ranks.begin(), ranks.end(), [](uint32_t r) { return r >= 16; }), 5);
  std::vector<uint32_t> decoded(3 * size_t(T)), predictors(3 * size_t(V));
  decode_traversal(code.symbols, code.references, T, V, decoded.data(), predictors.data(), "node", clusters);
  EXPECT_EQ(decoded, code.indices);
  EXPECT_EQ(predictors, code.predictors);
}

// The front's storage is kept per thread between calls: a smaller node after a larger one (every piece's end
// reading an edge the larger one left there, taken ones among them) and a larger one after it (the storage
// grown) decode as each does alone, in both decoders (with and without the further parallelograms).
TEST(TraversalConnectivity, FrontStorageKeptBetweenCallsOfAnySize) {
  struct Node {
    std::vector<uint32_t> indices;
    uint32_t V;
  };
  const Mesh large = sphere(1.0f, 24, 48);
  const std::vector<Node> nodes = {{large.indices, uint32_t(large.vertex_count())},
                                   {holed_grid(8, 1), 9 * 9},
                                   {holed_grid(16, 2), 17 * 17},
                                   {holed_grid(6, 3), 7 * 7}};
  for (int repeat = 0; repeat < 2; ++repeat) {
    for (const Node& n : nodes) {
      const uint32_t T = uint32_t(n.indices.size() / 3);
      const TraversalCode code = encode_traversal(n.indices, n.V);
      for (bool multi : {false, true}) {
        std::vector<uint32_t> decoded(3 * size_t(T)), predictors(3 * size_t(n.V));
        Parallelograms extra;
        decode_traversal(code.symbols, code.references, T, n.V, decoded.data(), predictors.data(), "node", {},
                         multi ? &extra : nullptr);
        EXPECT_EQ(decoded, code.indices) << T << " triangles, multi " << multi;
        if (!multi) {
          EXPECT_EQ(predictors, code.predictors) << T << " triangles";
        }
      }
    }
  }
}

// Fixed tables (traversal_tables.hpp): where vertices have about six triangles each (a sphere's rings, a
// grid), the gate's context names the kind most of the time, and the stream holds under a bit a gate (12
// classes alike would take 3.6; sphere(16, 32) 0.68, its poles' fans of 32 included).
TEST(TraversalConnectivity, RegularMeshesTakeUnderABitAGate) {
  for (const Mesh& m : {sphere(1.0f, 16, 32), grid(24)}) {
    const TraversalCode code = encode_traversal(m.indices, uint32_t(m.vertex_count()));
    const double bits = 8.0 * double(code.symbols.size()) / double(code.steps.size());
    EXPECT_LT(bits, 1.0) << code.symbols.size() << " B for " << code.steps.size() << " gates";
  }
}

// Either table set decodes (the stream names its own), and the encoder keeps the smaller stream.
TEST(TraversalConnectivity, EitherTableSetDecodesAndTheSmallerIsKept) {
  for (uint32_t seed = 0; seed < 4; ++seed) {
    const std::vector<uint32_t> indices = holed_grid(12, seed);
    const uint32_t T = uint32_t(indices.size() / 3), V = 13 * 13;
    const TraversalCode code = encode_traversal(indices, V);
    size_t smaller = SIZE_MAX;
    for (uint32_t set : {0u, 1u}) {
      const std::vector<uint8_t> stream = encode_traversal_steps(code.steps, set);
      smaller = std::min(smaller, stream.size());
      std::vector<uint32_t> decoded(3 * size_t(T)), predictors(3 * size_t(V));
      decode_traversal(stream, code.references, T, V, decoded.data(), predictors.data(), "node");
      EXPECT_EQ(decoded, code.indices) << "set " << set;
    }
    EXPECT_EQ(code.symbols.size(), smaller);
  }
}

// Streams changed at random (bytes, a byte less or more) decode to triangles within the node or throw
// lodstream::Error: never a read outside the stream (the ASan build checks that) nor another exception.
TEST(TraversalConnectivity, HostileSymbolStreamsAreErrors) {
  const std::vector<uint32_t> indices = holed_grid(12, 3);
  const uint32_t T = uint32_t(indices.size() / 3), V = 13 * 13;
  const TraversalCode code = encode_traversal(indices, V);
  std::mt19937 rng(5);
  size_t refused = 0;
  for (int i = 0; i < 600; ++i) {
    std::vector<uint8_t> bad = code.symbols;
    if (i % 3 == 1) bad.pop_back();
    if (i % 3 == 2) bad.push_back(uint8_t(rng()));
    for (int k = 0; k < 1 + i % 4; ++k) bad[rng() % bad.size()] = uint8_t(rng());
    std::vector<uint32_t> decoded(3 * size_t(T)), predictors(3 * size_t(V));
    try {
      decode_traversal(bad, code.references, T, V, decoded.data(), predictors.data(), "node");
      for (uint32_t v : decoded) EXPECT_LT(v, V);
    } catch (const Error&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 500u);  // the end checks (state back at its start, every byte read) catch most
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
  // The stream of gates of the given kinds at gates whose vertices lie in a and b decoded triangles (the
  // first gate, 0 -> 1 of the first triangle, lies in 1 and 1), each after the one before; tagged with the
  // cluster code of move-to-front rank `rank` (0: code 1, cluster 0; 1: code 2, cluster 1).
  struct Gate {
    TraversalSymbol kind;
    uint32_t a = 1, b = 1;
    bool tagged = false;
    uint8_t rank = 0;
  };
  auto stream = [](std::vector<Gate> gates) {
    std::vector<TraversalStep> steps;
    uint32_t previous = 0;
    for (const Gate& g : gates) {
      const uint8_t symbol_class = uint8_t(g.kind + (g.tagged ? 6 : 0));
      steps.push_back({uint16_t(traversal_context(previous, g.a, g.b)), symbol_class, g.rank});
      previous = symbol_class;
    }
    return encode_traversal_steps(steps, 0);
  };
  EXPECT_EQ(reason({}, 1, 3), "decoded");
  EXPECT_EQ(reason(stream({{kVertex}}), 2, 4), "decoded");
  EXPECT_EQ(reason({}, 2, 4), corrupted("symbols end early"));
  EXPECT_EQ(reason(stream({{kBoundary}}), 2, 4), corrupted("symbols end early"));
  EXPECT_EQ(reason(stream({{kVertex}}), 1, 4), corrupted("symbols left over"));
  // The rANS stream itself: too short for its state, a state below kLow, bytes left over or missing.
  EXPECT_EQ(reason({1, 2, 3, 4, 5, 6, 7}, 2, 4), corrupted("symbol stream shorter than its states"));
  EXPECT_EQ(reason({0, 0, 1, 0, 0, 0, 0, 0}, 2, 4), corrupted("invalid symbol state"));
  std::vector<uint8_t> longer = stream({{kVertex}});
  longer.insert(longer.end(), {7, 7});
  EXPECT_EQ(reason(longer, 2, 4), corrupted("symbols left over"));
  EXPECT_EQ(reason(stream({{kVertex}}), 2, 3), corrupted("more vertices than the node holds"));
  EXPECT_EQ(reason(stream({{kVertex, 1, 1, true, 1}}), 2, 4), corrupted("cluster out of range"));
  // kLeft leaves a loop of 2 (the first triangle's second edge and the new one): no turn there. Its next
  // gate, 1 -> 2, lies in 2 and 2 triangles; after a kVertex in 2 and 1.
  EXPECT_EQ(reason(stream({{kLeft}}), 2, 3), "decoded");
  EXPECT_EQ(reason(stream({{kLeft}, {kLeft, 2, 2}}), 3, 3), corrupted("left turn in a loop of 2"));
  EXPECT_EQ(reason(stream({{kLeft}, {kRight, 2, 2}}), 3, 3), corrupted("right turn in a loop of 2"));
  EXPECT_EQ(reason(stream({{kLeft}, {kEnd, 2, 2}}), 3, 3), corrupted("end of a loop that is not 3 edges"));
  EXPECT_EQ(reason(stream({{kVertex}, {kEnd, 2, 1}}), 3, 4), corrupted("end of a loop that is not 3 edges"));
  EXPECT_EQ(reason(stream({{kEnd}}), 2, 3), "decoded");
  EXPECT_EQ(reason(stream({{kSplit}}), 2, 4, {0, 0, 0, 2}), "decoded");
  EXPECT_EQ(reason(stream({{kSplit}}), 2, 4, {0, 0, 0, 3}),
            corrupted("reference to a vertex not decoded yet"));
  EXPECT_EQ(reason(stream({{kVertex}}), 2, 4, {0, 0, 0, 0}), corrupted("references left over"));
  // Two clusters of one triangle each: the second triangle tagged with cluster 1 (code 2), or left in the
  // gate's cluster 0, which is then full.
  EXPECT_EQ(reason(stream({{kVertex, 1, 1, true, 1}}), 2, 4, {0, 0, 0, 0}, {1, 1}), "decoded");
  EXPECT_EQ(reason(stream({{kVertex}}), 2, 4, {0, 0, 0, 0}, {1, 1}),
            corrupted("triangles per cluster differ from the header's"));
}

}  // namespace
}  // namespace lodstream::test
