// Where a package's index bytes go: for each field of the node records (index.hpp: heads, deltas, locations,
// counts, links, error/sphere pairs), its raw bytes and its bytes after zstd, summed over the root index's
// run of records and every index page's. The stored index pages zstd a whole run at once, so a field's bytes
// after zstd are measured by compressing that field's stream of each run alone, as the writer compresses an
// index page: the sum over fields is close to, not equal to, the stored bytes, which are given too (the root
// index's stored bytes include the scene and the tables, not only its records). Used by `lodstream inspect
// --parts`.
#pragma once

#include <array>
#include <cstdint>

#include "package/index.hpp"
#include "package/reader.hpp"

namespace lodstream::package {

struct IndexAccount {
  uint64_t records = 0;                                    // node records accounted (all of the package's)
  std::array<uint64_t, kIndexFields> raw{}, compressed{};  // per field (kIndexFieldNames)
  uint64_t root_stored = 0, pages_stored = 0;              // the stored root index; the stored index pages
};

// The account of every node record of `reader`'s package (loads every index page: one read each), each field
// of each run compressed alone at `zstd_level` (the writer's index level). Throws lodstream::Error like the
// reader.
IndexAccount account_index(PackageReader& reader, int zstd_level = 9);

}  // namespace lodstream::package
