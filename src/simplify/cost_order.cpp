// The collapse loop's order: see cost_order.hpp.
#include "simplify/cost_order.hpp"

#include <algorithm>
#include <bit>

#include "core/counting_sort.hpp"

namespace lodstream::simplify {

void sort_by_cost(UninitializedVector<Ranked>& items, UninitializedVector<Ranked>& scratch,
                  std::vector<uint64_t>& keys, size_t small) {
  const size_t n = items.size();
  scratch.resize(n);
  if (n <= small) {
    // The index breaks ties, as the radix sort's stability does; the keys are distinct.
    keys.resize(n);
    for (uint32_t i = 0; i < n; ++i) keys[i] = uint64_t(std::bit_cast<uint32_t>(items[i].cost)) << 32 | i;
    std::sort(keys.begin(), keys.end());
    for (size_t k = 0; k < n; ++k) scratch[k] = items[uint32_t(keys[k])];
    items.swap(scratch);
    return;
  }
  UninitializedVector<Ranked>*src = &items, *dst = &scratch;
  for (int shift : {0, 11, 22}) {
    auto digit = [&, shift](size_t i) { return (std::bit_cast<uint32_t>((*src)[i].cost) >> shift) & 2047u; };
    counting_sort(n, 2048, digit, [&](size_t i, uint32_t position) { (*dst)[position] = (*src)[i]; });
    std::swap(src, dst);
  }
  if (src != &items) items.swap(scratch);
}

}  // namespace lodstream::simplify
