#include "schedule/cache_budget.hpp"

#include <cmath>

namespace lodstream::schedule {

uint64_t affordable_triangles(const package::RootIndex& root, uint64_t cache_bytes) {
  uint64_t raw = 0;
  for (const package::Range& page : root.pages) raw += page.raw_size;
  const uint64_t input = root.scene.input_triangles;
  if (raw <= cache_bytes || input == 0) return UINT64_MAX;
  return uint64_t(std::floor(double(cache_bytes) * double(input) / double(raw)));
}

}  // namespace lodstream::schedule
