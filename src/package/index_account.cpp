#include "package/index_account.hpp"

#include "package/format.hpp"

namespace lodstream::package {

IndexAccount account_index(PackageReader& reader, int zstd_level) {
  IndexAccount a;
  const RootIndex& root = reader.root();
  auto add_run = [&](std::span<const NodeRecord> records, uint32_t first_id) {
    const auto fields = serialize_node_fields(records, first_id);
    for (size_t f = 0; f < kIndexFields; ++f) {
      a.raw[f] += fields[f].size();
      if (!fields[f].empty()) a.compressed[f] += zstd_compress(fields[f], zstd_level).size();
    }
    a.records += records.size();
  };
  add_run(root.root_nodes, 0);
  std::vector<NodeRecord> run;
  for (const IndexPage& page : root.index_pages) {
    run.clear();
    for (uint32_t id = page.first_node; id < page.first_node + page.node_count; ++id)
      run.push_back(reader.node(id));
    add_run(run, page.first_node);
    a.pages_stored += page.range.size;
  }
  a.root_stored = reader.header().root_size;
  return a;
}

}  // namespace lodstream::package
