// sort_edges (group_partition.hpp): the radix sort of cluster boundary edges gives the order of a comparison
// sort (by key, then cluster) for edge counts and id ranges that take one to four digit passes of every
// digit width, repeated keys included.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "hierarchy/group_partition.hpp"

namespace lodstream::hierarchy {
namespace {

// `edges` random edges over ids [0, ids), listed by increasing cluster, each key shared by about
// `sharing` clusters (as boundary edges of neighbouring clusters are).
std::vector<ClusterEdge> random_edges(size_t edges, uint32_t ids, uint32_t sharing, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<uint32_t> id(0, ids - 1);
  std::vector<uint64_t> keys(std::max<size_t>(1, edges / sharing));
  for (uint64_t& k : keys) {
    uint32_t a = id(rng), b = id(rng);
    while (b == a) b = id(rng);
    k = uint64_t(std::min(a, b)) << 32 | std::max(a, b);
  }
  std::uniform_int_distribution<size_t> pick(0, keys.size() - 1);
  std::vector<ClusterEdge> out;
  for (uint32_t cluster = 0; out.size() < edges; ++cluster)
    for (int k = 0; k < 3 && out.size() < edges; ++k) out.emplace_back(keys[pick(rng)], cluster);
  return out;
}

TEST(GroupPartition, SortEdgesMatchesAComparisonSort) {
  struct Case {
    size_t edges;
    uint32_t ids, sharing;
  };
  for (const Case& c :
       {Case{1, 2, 1}, Case{2, 3, 2}, Case{100, 16, 2}, Case{1000, 200, 2}, Case{5000, 70000, 2},
        Case{20000, 5000, 1}, Case{300000, 3000000, 2}, Case{200000, 2000000000u, 3}}) {
    std::vector<ClusterEdge> edges = random_edges(c.edges, c.ids, c.sharing, uint32_t(c.edges + c.ids));
    std::vector<ClusterEdge> expected = edges;
    std::sort(expected.begin(), expected.end());
    sort_edges(edges, c.ids);
    EXPECT_EQ(edges, expected) << c.edges << " edges over " << c.ids << " ids";
  }
}

TEST(GroupPartition, SortEdgesOfNoEdges) {
  std::vector<ClusterEdge> edges;
  sort_edges(edges, 10);
  EXPECT_TRUE(edges.empty());
}

}  // namespace
}  // namespace lodstream::hierarchy
