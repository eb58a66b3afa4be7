#include "package/size_account.hpp"

#include <map>

#include "package/format.hpp"

namespace lodstream::package {

const char* node_part_name(NodePart part) {
  static constexpr const char* kNames[kNodeParts] = {"header", "positions",    "normals",   "attributes",
                                                     "locked", "connectivity", "references"};
  return kNames[uint32_t(part)];
}

std::vector<LevelAccount> account_sizes(PackageReader& reader, const SizeAccountOptions& options) {
  const uint32_t N = reader.node_count();
  const std::vector<Range>& ranges = reader.root().pages;
  std::vector<std::vector<uint32_t>> on_page(ranges.size());
  for (uint32_t id = 0; id < N; ++id) {
    const NodeRecord& n = reader.node(id);
    if (n.encoding == NodeEncoding::codec) on_page[n.page].push_back(id);
  }
  struct Level {
    LevelAccount account;
    std::array<std::vector<uint8_t>, kNodeParts> bytes;
  };
  std::map<uint32_t, Level> levels;
  for (uint32_t page = 0; page < ranges.size(); ++page) {
    if (on_page[page].empty()) continue;
    const std::vector<uint8_t> raw = reader.read_page(page);
    uint64_t page_raw = 0;  // the page's node bytes, each record once
    for (size_t k = 0; k < on_page[page].size(); ++k) {
      const NodeRecord& n = reader.node(on_page[page][k]);
      if (k == 0 || n.offset != reader.node(on_page[page][k - 1]).offset) page_raw += n.size;
    }
    for (size_t k = 0; k < on_page[page].size(); ++k) {
      const uint32_t id = on_page[page][k];
      const NodeRecord& n = reader.node(id);
      Level& l = levels[n.level];
      l.account.level = n.level;
      ++l.account.nodes, l.account.triangles += n.triangles;
      // A record's bytes and stored vertices go to the level of its first cluster (a DAG group's input
      // clusters: one level, but for a cluster left over from an abandoned group).
      if (k > 0 && n.offset == reader.node(on_page[page][k - 1]).offset) continue;
      const std::span<const uint8_t> bytes = reader.node_bytes(id, raw);
      const NodeSizeBreakdown b = reader.codec().breakdown(bytes, "node " + std::to_string(id));
      const size_t sizes[kNodeParts] = {b.header, b.positions(),      b.normals, b.attributes,
                                        b.locked, b.indices - b.tail, b.tail};
      l.account.vertices += b.stored_vertices;
      l.account.page_bytes += double(ranges[page].size) * double(n.size) / double(page_raw);
      size_t at = 0;
      for (uint32_t p = 0; p < kNodeParts; ++p) {  // the parts are consecutive (node_codec.hpp)
        const auto part = bytes.subspan(at, sizes[p]);
        l.bytes[p].insert(l.bytes[p].end(), part.begin(), part.end());
        l.account.parts[p].raw += sizes[p], at += sizes[p];
      }
    }
  }
  std::vector<LevelAccount> out;
  for (auto& [level, l] : levels) {
    for (uint32_t p = 0; p < kNodeParts; ++p)
      for (size_t at = 0; at < l.bytes[p].size(); at += options.chunk) {
        const auto chunk = std::span(l.bytes[p]).subspan(at, std::min(options.chunk, l.bytes[p].size() - at));
        l.account.parts[p].compressed += zstd_compress(chunk, options.zstd_level, options.min_match).size();
      }
    out.push_back(l.account);
  }
  return out;
}

}  // namespace lodstream::package
