// IndexPageMap against a search over the pages, for page sizes around its 64-id buckets.
#include <gtest/gtest.h>

#include <algorithm>

#include "package/index_page_map.hpp"

namespace lodstream::test {

using package::IndexPage;
using package::IndexPageMap;
using package::kNone;
using package::RootIndex;

namespace {

// The root index holds ids [0, roots); then pages of the given node counts in order.
RootIndex root_with_pages(uint32_t roots, const std::vector<uint32_t>& counts) {
  RootIndex root;
  root.root_nodes.resize(roots);
  uint32_t first = roots;
  for (uint32_t count : counts) {
    IndexPage p;
    p.first_node = first;
    p.node_count = count;
    root.index_pages.push_back(p);
    first += count;
  }
  root.node_count = first;
  return root;
}

uint32_t searched(const RootIndex& root, uint32_t id) {
  if (id < root.root_nodes.size()) return kNone;
  for (uint32_t p = 0; p < root.index_pages.size(); ++p)
    if (id < root.index_pages[p].first_node + root.index_pages[p].node_count) return p;
  return kNone;
}

}  // namespace

TEST(IndexPageMap, EveryIdFindsThePageThatHoldsIt) {
  // Pages larger than a bucket, exactly one, single records (many in one bucket), and a ragged end.
  const std::vector<std::vector<uint32_t>> layouts{
      {300, 64, 1, 1, 1, 63, 65, 128, 7}, std::vector<uint32_t>(200, 1), {1000}, {}};
  for (uint32_t roots : {0u, 1u, 37u, 64u}) {
    for (const auto& counts : layouts) {
      const RootIndex root = root_with_pages(roots, counts);
      const IndexPageMap map(root);
      for (uint32_t id = 0; id < root.node_count; ++id)
        ASSERT_EQ(map.page_of(id), searched(root, id)) << "roots " << roots << ", id " << id;
    }
  }
}

}  // namespace lodstream::test
