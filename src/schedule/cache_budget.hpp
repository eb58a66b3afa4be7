// The triangles a client's page cache affords. A cut of T triangles needs its nodes' pages in the cache
// (decompressed), and a page also holds nodes the cut does not draw (other levels and neighbours stored with
// them), so a triangle is priced at the package's decompressed page bytes per INPUT triangle: in a cluster
// DAG, which stores about two triangles per input triangle, about twice its bytes per stored triangle, which
// leaves room for those other nodes and for the predicted views' pages. Scheduling (push and pull) and the
// drawn cut take it as a triangle budget, so a client whose cache is smaller than the cut at tau needs
// converges to a coarser cut (a raised tau) instead of evicting and fetching the same pages again and again.
#pragma once

#include <cstdint>

#include "package/index.hpp"

namespace lodstream::schedule {

// cache_bytes * input triangles / (decompressed bytes of every data page); no limit (UINT64_MAX) when the
// whole package fits or the package does not say how many triangles it was baked from. Cost: O(pages).
uint64_t affordable_triangles(const package::RootIndex& root, uint64_t cache_bytes);

}  // namespace lodstream::schedule
