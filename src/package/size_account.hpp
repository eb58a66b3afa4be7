// Where a package's bytes go: per level, per part of the nodes (header, positions, normals, other attributes,
// locked stream, connectivity, references), raw and after zstd, with the vertices each level stores per
// triangle (a cluster's border vertices repeat in every record that holds it; a record of several clusters
// stores them once, and its bytes and vertices count at the level of its first cluster). The pages' zstd runs
// over whole pages, so a part's bytes after zstd are measured by compressing that part alone: each level's
// bytes of that part, in node order, cut into chunks of `chunk` bytes (the size of a page), each compressed
// as the writer compresses a page. The sum over parts is therefore close to, not equal to, the pages' stored
// bytes, which are given per level as well (a page's stored bytes shared among the levels of its nodes by
// their raw bytes). Used by `lodstream inspect --parts` and the package benchmark.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "package/reader.hpp"

namespace lodstream::package {

// connectivity: the nodes' connectivity streams (codec 3: the traversal's symbols), compressed as a page
// stores them (page_parts.hpp: zstd'd; codec 3's are rANS streams already); references: the rest of
// the nodes' connectivity bytes (NodeSizeBreakdown::tail; codec 3: the traversal's references).
enum class NodePart : uint32_t { header, positions, normals, attributes, locked, connectivity, references };
inline constexpr uint32_t kNodeParts = 7;
// "header", "positions", ... as in the JSON of inspect --parts.
const char* node_part_name(NodePart part);

struct PartBytes {
  uint64_t raw = 0, compressed = 0;
};

struct LevelAccount {
  uint32_t level = 0;
  uint64_t nodes = 0, triangles = 0, vertices = 0;
  std::array<PartBytes, kNodeParts> parts{};
  double page_bytes = 0.0;  // stored (zstd) data-page bytes attributed to this level
};

struct SizeAccountOptions {
  int zstd_level = 9, min_match = 6;  // the writer's for codecs 2 and 3 (writer.hpp)
  size_t chunk = 32768;
};

// The account of every codec node of the package, by level (ascending). Reads and decompresses every data
// page once (loading every index page); parses each node's header only (NodeCodec::breakdown). Cost: one
// read of the package plus a zstd compression of its raw node bytes. Throws lodstream::Error like the reader.
std::vector<LevelAccount> account_sizes(PackageReader& reader, const SizeAccountOptions& options = {});

}  // namespace lodstream::package
