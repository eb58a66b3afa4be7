// Welding by hash: for items 0..n-1 with an equality (equal positions, equal vertices) and a 64-bit hash
// that agrees with it, each item's representative, the smallest item equal to it. The items are dealt by
// the hash's top bits into buckets of about 1024 on every core (counting_sort.hpp, which keeps increasing
// items in each), and each bucket resolved through a small per-thread table of (32 hash
// bits, item) slots at load <= 0.5 that stays in cache, buckets on every core. One table over all items
// (one cache miss per item, on one core) took 0.7 CPU-s on 2.8 M positions, mostly first touches of its
// pages.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <numeric>
#include <vector>

#include "core/counting_sort.hpp"
#include "core/prefault.hpp"

namespace lodstream {

// rep[i] = the smallest j with equal(j, i) (rep[i] == i for the first of each class). hash(i) must be equal
// for equal items; it is called three times per item, so an expensive one is better computed once into an
// array by the caller (which then costs 8 bytes per item; the DAG's level-0 weld, at the bake's peak memory,
// recomputes its cheap one). equal(a, b) is called only for items whose hashes agree in their low 32 bits.
// Cost: O(n) expected on every core; 4 bytes per item of scratch besides the result.
template <class Hash, class Equal>
std::vector<uint32_t> representatives(size_t n, const Hash& hash, const Equal& equal) {
  const int bucket_bits = std::min(16, int(std::bit_width(n / 1024)));
  const size_t buckets = size_t(1) << bucket_bits;
  auto bucket_of = [&](size_t i) {
    return bucket_bits == 0 ? size_t(0) : size_t(hash(i) >> (64 - bucket_bits));
  };
  std::vector<uint32_t> order, bucket_begin, rep;
  resize_prefaulted(order, n), resize_prefaulted(rep, n);  // written on every core, zero-filled on one
  // One bucket (fewer than 1024 items: a DAG group's weld) holds the items in order: the sort would only
  // copy them (elephant_1m bake, callgrind: the simplifier weld's counting sorts, 90.1 -> 0.1 M
  // instructions).
  if (buckets == 1)
    std::iota(order.begin(), order.end(), 0u), bucket_begin = {0, uint32_t(n)};
  else
    counting_sort(
        n, uint32_t(buckets), bucket_of, [&](size_t i, uint32_t at) { order[at] = uint32_t(i); },
        &bucket_begin);
  auto resolve = [&](const tbb::blocked_range<size_t>& r) {
    constexpr uint64_t kEmpty = UINT64_MAX;
    thread_local std::vector<uint64_t> table;
    for (size_t b = r.begin(); b < r.end(); ++b) {
      const uint32_t begin = bucket_begin[b], end = bucket_begin[b + 1];
      const size_t capacity = std::bit_ceil(std::max<size_t>(16, 2 * size_t(end - begin)));
      if (table.size() < capacity) table.resize(capacity);
      std::fill_n(table.begin(), capacity, kEmpty);
      for (uint32_t k = begin; k < end; ++k) {
        const uint32_t i = order[k];
        const uint64_t h = hash(i), tag = uint32_t(h);
        for (size_t slot = h & (capacity - 1);; slot = (slot + 1) & (capacity - 1)) {
          const uint64_t e = table[slot];
          if (e == kEmpty) {
            table[slot] = tag << 32 | i;
            rep[i] = i;
            break;
          }
          if (e >> 32 == tag && equal(uint32_t(e), i)) {
            rep[i] = uint32_t(e);
            break;
          }
        }
      }
    }
  };
  // One bucket (fewer than 1024 items: a DAG group's weld) is resolved in place, without a nested TBB call.
  if (buckets == 1)
    resolve(tbb::blocked_range<size_t>(0, 1));
  else
    tbb::parallel_for(tbb::blocked_range<size_t>(0, buckets, 16), resolve);
  return rep;
}

}  // namespace lodstream
