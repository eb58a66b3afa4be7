// The collapse loop's order: a pass's candidates sorted by cost. Internal to src/simplify.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "simplify/uninitialized.hpp"

namespace lodstream::simplify {

// A candidate in a pass's collapse order: its cost (>= 0, not NaN) and its slot (the simplifier's per-corner
// candidate, or an index into such a list).
struct Ranked {
  float cost;
  uint32_t slot;
};

// Candidates of at most this many are sorted by one std::sort, larger ones by the radix sort (sort_by_cost):
// the best of 200 sorts of n random costs on this machine, radix / std::sort, n = 1024: 7.4 / 4.3 us, 2048:
// 12.1 / 9.2 us, 4096: 21.6 / 20.5 us.
constexpr size_t kSmallCostSort = 2048;

// Sorts `items` by cost, stably (equal costs keep their order), comparing the costs' float bits (costs are
// >= 0, so their bits order like them). Up to `small` items: one std::sort of (cost bits, index) keys in
// `keys`, O(n log n); more: an LSD radix sort, 11 + 11 + 10 bits, each digit a counting_sort on every core
// (core/counting_sort.hpp), O(n) plus about 75,000 instructions of fixed cost (three 2048-bucket counts: a
// clear, a prefix sum and an allocation each), which took 5.6 % of the bake's group simplification on
// elephant_1m. Both give the same order. `scratch` and `keys` are working space, reused across calls.
void sort_by_cost(UninitializedVector<Ranked>& items, UninitializedVector<Ranked>& scratch,
                  std::vector<uint64_t>& keys, size_t small = kSmallCostSort);

}  // namespace lodstream::simplify
