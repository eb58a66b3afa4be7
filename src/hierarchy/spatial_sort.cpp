#include "hierarchy/spatial_sort.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <memory>
#include <span>
#include <utility>

#include "core/counting_sort.hpp"
#include "core/morton.hpp"
#include "core/prefault.hpp"

namespace lodstream::hierarchy {

namespace {

// morton_spread10 of every 10-bit value: a code is then three look-ups (4 KB, in cache) instead of three
// spreads of 13 operations each (callgrind, bake of data/horse.ply: 2,344.9 -> 2,338.3 M instructions).
constexpr std::array<uint32_t, 1024> kSpread10 = [] {
  std::array<uint32_t, 1024> spread{};
  for (uint32_t v = 0; v < 1024; ++v) spread[v] = morton_spread10(v);
  return spread;
}();

// morton_code10(x, y, z) for coordinates below 1024.
uint32_t morton_code(uint32_t x, uint32_t y, uint32_t z) {
  return kSpread10[x & 1023] | kSpread10[y & 1023] << 1 | kSpread10[z & 1023] << 2;
}

// Sorts a run of (code << 32 | triangle) keys whose codes share their top 10 bits and whose triangles
// increase (as counting_sort deals them): two stable counting passes by the code's bits 0-9, then 10-19,
// give the order of a sort by (code, triangle) in O(n + 1024) instead of O(n log n); runs under 256 keys,
// where the 1024-entry counts cost more, are sorted plainly (the keys are distinct: the same order).
// `scratch` is resized to the run.
void sort_run(std::span<uint64_t> keys, std::vector<uint64_t>& scratch) {
  if (keys.size() < 256) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  scratch.resize(keys.size());
  std::span<uint64_t> from = keys, to = scratch;
  for (int shift : {32, 42}) {
    uint32_t start[1024] = {};
    for (uint64_t k : from) ++start[k >> shift & 1023];
    uint32_t position = 0;
    for (uint32_t& s : start) position += std::exchange(s, position);
    for (uint64_t k : from) to[start[k >> shift & 1023]++] = k;
    std::swap(from, to);
  }
}

}  // namespace

std::vector<uint32_t> spatial_sort_triangles(std::span<const glm::vec3> positions,
                                             std::span<const uint32_t> indices) {
  const size_t n = indices.size() / 3;
  // The large arrays zero-filled on the calling thread are prefaulted on every core first (core/prefault.hpp;
  // elephant_5m's level 0: 136 MB, cleared by the kernel on one core while the other waited).
  std::vector<uint32_t> sorted;
  resize_prefaulted(sorted, n * 3);
  if (n == 0) return sorted;
  // Centroids, with the same operations in the same order as meshoptimizer, and their bounding box.
  auto centroid = std::make_unique_for_overwrite<glm::vec3[]>(n);  // every entry written below
  struct Box {
    glm::vec3 lo{FLT_MAX}, hi{-FLT_MAX};
  };
  auto centroids = [&](size_t begin, size_t end, Box b) {
    for (size_t t = begin; t < end; ++t) {
      const glm::vec3 &a = positions[indices[3 * t]], &c1 = positions[indices[3 * t + 1]],
                      &c2 = positions[indices[3 * t + 2]];
      const glm::vec3 m((a.x + c1.x + c2.x) / 3.f, (a.y + c1.y + c2.y) / 3.f, (a.z + c1.z + c2.z) / 3.f);
      centroid[t] = m;
      b.lo = glm::min(b.lo, m), b.hi = glm::max(b.hi, m);
    }
    return b;
  };
  const bool parallel = n >= kParallelSortTriangles;
  const Box box =
      !parallel
          ? centroids(0, n, Box{})
          : tbb::parallel_reduce(
                tbb::blocked_range<size_t>(0, n), Box{},
                [&](const tbb::blocked_range<size_t>& r, Box b) { return centroids(r.begin(), r.end(), b); },
                [](Box a, const Box& b) {
                  return Box{glm::min(a.lo, b.lo), glm::max(a.hi, b.hi)};
                });
  float extent = 0.0f;
  for (int a = 0; a < 3; ++a) extent = std::max(extent, box.hi[a] - box.lo[a]);
  const float scale = extent == 0.0f ? 0.0f : 1.0f / extent;

  // (code << 32 | triangle): sorting these sorts by code, ties by triangle (a stable sort by code).
  auto code_of = [&](size_t t) {
    const glm::vec3 q = (centroid[t] - box.lo) * scale * 1023.f + 0.5f;
    return morton_code(uint32_t(int(q.x)), uint32_t(int(q.y)), uint32_t(int(q.z)));
  };
  std::vector<uint64_t> order;
  if (!parallel) {
    order.resize(n);
    for (size_t t = 0; t < n; ++t) order[t] = uint64_t(code_of(t)) << 32 | t;
    std::sort(order.begin(), order.end());
  } else {
    // The triangles are dealt by the code's top 10 bits into 1024 runs (core/counting_sort.hpp), then each
    // run is sorted in cache.
    constexpr int kRunBits = 10;
    constexpr size_t kRuns = size_t(1) << kRunBits;
    std::vector<uint32_t> code;
    resize_prefaulted(code, n), reserve_prefaulted(order, n);
    tbb::parallel_for(size_t(0), n, [&](size_t t) { code[t] = code_of(t); });
    centroid.reset();
    std::vector<uint32_t> run_begin;
    order.resize(n);
    counting_sort(
        n, kRuns, [&](size_t t) { return code[t] >> (30 - kRunBits); },
        [&](size_t t, uint32_t at) { order[at] = uint64_t(code[t]) << 32 | t; }, &run_begin);
    code = {};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, kRuns, 8), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<uint64_t> scratch;  // freed after these runs: a run may hold most triangles
      for (size_t run = r.begin(); run < r.end(); ++run)
        sort_run(std::span(order).subspan(run_begin[run], run_begin[run + 1] - run_begin[run]), scratch);
    });
  }
  auto gather = [&](size_t i) {
    const size_t t = uint32_t(order[i]);
    sorted[3 * i] = indices[3 * t], sorted[3 * i + 1] = indices[3 * t + 1],
               sorted[3 * i + 2] = indices[3 * t + 2];
  };
  if (parallel)
    tbb::parallel_for(size_t(0), n, gather);
  else
    for (size_t i = 0; i < n; ++i) gather(i);
  return sorted;
}

}  // namespace lodstream::hierarchy
