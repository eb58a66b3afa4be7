// A stable counting sort into buckets on every core: items 0..n-1 are dealt by bucket_of(i) into `buckets`
// consecutive runs, each run keeping increasing i. The items are cut into chunks of 2^16, each chunk counts
// its own buckets (in parallel), a prefix over (bucket, chunk) gives every chunk its place in every run, and
// each chunk scatters its items there (in parallel). Used where a large array is split into pieces that are
// then handled in cache (representatives.hpp, the spatial sort's runs).
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace lodstream {

// Fills `out` (n entries) with value(i) in the order above and `begin` (buckets + 1 entries) with where each
// bucket's run starts (begin[buckets] = n); bucket_of(i) < buckets is called twice per item, value(i) once.
// Cost: O(n + chunks * buckets) on every core, 4 bytes per (chunk, bucket) of scratch.
template <class T, class BucketOf, class Value>
void bucket_sort(size_t n, size_t buckets, const BucketOf& bucket_of, const Value& value, std::vector<T>& out,
                 std::vector<uint32_t>& begin) {
  constexpr size_t kChunk = size_t(1) << 16;
  const size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<uint32_t> start(chunks * buckets, 0);  // chunk-major: start[chunk * buckets + bucket]
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    uint32_t* count = &start[c * buckets];
    for (size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) ++count[bucket_of(i)];
  });
  begin.assign(buckets + 1, 0);
  uint32_t running = 0;
  for (size_t b = 0; b < buckets; ++b) {
    begin[b] = running;
    for (size_t c = 0; c < chunks; ++c) {
      const uint32_t k = start[c * buckets + b];
      start[c * buckets + b] = running;
      running += k;
    }
  }
  begin[buckets] = running;
  out.resize(n);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    uint32_t* next = &start[c * buckets];
    for (size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) out[next[bucket_of(i)]++] = value(i);
  });
}

}  // namespace lodstream
