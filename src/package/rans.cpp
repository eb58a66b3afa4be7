#include "package/rans.hpp"

#include <algorithm>

namespace lodstream::package::rans {

void normalize(std::span<const uint32_t> counts, uint64_t total, uint32_t scale_bits,
               std::span<uint32_t> frequencies) {
  const uint64_t scale = uint64_t(1) << scale_bits;
  uint64_t sum = 0;
  for (size_t s = 0; s < counts.size(); ++s) {
    frequencies[s] = counts[s] ? std::max<uint32_t>(1, uint32_t(uint64_t(counts[s]) * scale / total)) : 0;
    sum += frequencies[s];
  }
  // Rounding down leaves at most one per symbol short; rounding up to 1 at most one per symbol over: the
  // largest frequency takes the difference (over several steps if it would fall below 1).
  while (sum != scale) {
    const size_t largest =
        size_t(std::max_element(frequencies.begin(), frequencies.end()) - frequencies.begin());
    if (sum < scale) {
      frequencies[largest] += uint32_t(scale - sum), sum = scale;
    } else {
      const uint32_t d = std::min<uint32_t>(uint32_t(sum - scale), frequencies[largest] - 1);
      frequencies[largest] -= d, sum -= d;
    }
  }
}

}  // namespace lodstream::package::rans
