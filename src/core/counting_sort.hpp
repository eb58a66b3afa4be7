// A stable counting sort whose two scans run on all cores: the simplifier's face and candidate orders, and
// large arrays dealt into runs that are then handled in cache (representatives.hpp, io's weld, the spatial
// sort).
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace lodstream {

// Places the items 0..n-1 by bucket, stably: write(i, position) is called once for every item whose
// key(i) < buckets, with positions grouped by bucket in increasing order and, within a bucket, in the
// order of i (items whose key is >= buckets are left out). When `starts` is given it receives the first
// position of each bucket and, last, the number of items placed (buckets + 1 entries). The result is the
// same as one serial pass; blocks of items count their keys, then each block writes from its own offsets,
// in parallel. key and write may be called from several threads at once (write at distinct positions).
// Cost: O(n + blocks x buckets), two calls of key per item.
template <class Key, class Write>
void counting_sort(size_t n, uint32_t buckets, Key&& key, Write&& write,
                   std::vector<uint32_t>* starts = nullptr) {
  constexpr size_t kBlock = size_t(1) << 16;
  const size_t blocks = std::max<size_t>(1, (n + kBlock - 1) / kBlock);
  std::vector<uint32_t> offset(blocks * size_t(buckets), 0);  // offset[b * buckets + k]
  // f(b) for every block; one block (a DAG group's simplification sorts a few thousand items at a time)
  // runs in place, without a nested TBB call (about 800 instructions each).
  auto over_blocks = [blocks](auto&& f) {
    if (blocks == 1)
      f(size_t(0));
    else
      tbb::parallel_for(size_t(0), blocks, f);
  };
  over_blocks([&](size_t b) {
    uint32_t* count = &offset[b * buckets];
    for (size_t i = b * kBlock, e = std::min(n, i + kBlock); i < e; ++i)
      if (const uint32_t k = key(i); k < buckets) ++count[k];
  });
  if (starts) starts->assign(size_t(buckets) + 1, 0);
  uint32_t position = 0;
  for (uint32_t k = 0; k < buckets; ++k) {
    if (starts) (*starts)[k] = position;
    for (size_t b = 0; b < blocks; ++b) {
      const uint32_t count = offset[b * buckets + k];
      offset[b * buckets + k] = position;
      position += count;
    }
  }
  if (starts) (*starts)[buckets] = position;
  over_blocks([&](size_t b) {
    uint32_t* next = &offset[b * buckets];
    for (size_t i = b * kBlock, e = std::min(n, i + kBlock); i < e; ++i)
      if (const uint32_t k = key(i); k < buckets) write(i, next[k]++);
  });
}

}  // namespace lodstream
