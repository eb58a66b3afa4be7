// Which index page holds a node's record (index.hpp: the root index holds ids [0, root_nodes), then the
// index pages cover the rest in order, each a run of consecutive ids). A client and a push server ask this
// for every record a cut traversal reads, so it is a table lookup, not a search: the page of every 64th id,
// then a forward step while the next page starts at or below the id (rarely any: pages hold hundreds of
// records). Memory: 4 bytes per 64 nodes and per index page; self-contained (copies what it needs), so it
// moves with its owner. Built from a validated RootIndex (parse_root checks that the pages cover
// [root_nodes, node_count) in order).
#pragma once

#include <cstdint>
#include <vector>

#include "package/index.hpp"

namespace lodstream::package {

class IndexPageMap {
 public:
  // Cost: O(node_count / 64 + index pages).
  explicit IndexPageMap(const RootIndex& root);
  // The index page holding node `id`'s record, or kNone when the root index holds it; `id` must be below
  // root.node_count. Cost: O(1) (plus the pages starting within id's 64-id bucket).
  uint32_t page_of(uint32_t id) const {
    if (id < roots_) return kNone;
    uint32_t page = bucket_page_[(id - roots_) >> kBucketBits];
    while (page + 1 < first_node_.size() && first_node_[page + 1] <= id) ++page;
    return page;
  }

 private:
  static constexpr int kBucketBits = 6;
  uint32_t roots_ = 0;
  std::vector<uint32_t> first_node_;   // by index page
  std::vector<uint32_t> bucket_page_;  // the page of id roots_ + (bucket << kBucketBits)
};

}  // namespace lodstream::package
