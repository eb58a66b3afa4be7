#include "package/index_page_map.hpp"

namespace lodstream::package {

IndexPageMap::IndexPageMap(const RootIndex& root) : roots_(uint32_t(root.root_nodes.size())) {
  for (const IndexPage& p : root.index_pages) first_node_.push_back(p.first_node);
  const uint32_t paged = root.node_count > roots_ ? root.node_count - roots_ : 0;
  bucket_page_.resize((size_t(paged) + (1u << kBucketBits) - 1) >> kBucketBits);
  uint32_t page = 0;
  for (size_t b = 0; b < bucket_page_.size(); ++b) {
    const uint64_t id = roots_ + (uint64_t(b) << kBucketBits);
    while (page + 1 < first_node_.size() && first_node_[page + 1] <= id) ++page;
    bucket_page_[b] = page;
  }
}

}  // namespace lodstream::package
