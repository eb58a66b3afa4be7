#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <memory>
#include <utility>

#include "package/node_codec.hpp"

namespace lodstream::package {

PositionGrid PositionGrid::for_bounds(const Bounds& bounds, double bits) {
  PositionGrid g;
  float diagonal = bounds.diagonal();
  g.origin = bounds.empty() ? glm::vec3(0.0f) : bounds.min;
  // exp2 of a whole number is a power of two, so whole bits give exactly ldexp(diagonal, -bits).
  g.step = diagonal > 0.0f ? float(double(diagonal) * std::exp2(-bits)) : 1.0f;
  return g;
}

namespace {

// separating() refines a bit that separates to 2^-3 of a bit: elephant_5m collides at 15 bits (one pair of
// distinct positions on one grid point) and separates at 15.125, which stores its finest level 0.875 bits
// per coordinate cheaper than 16. Each halving is one more separates() pass (elephant_5m ~0.08 s).
constexpr int kFractionHalvings = 3;

struct Cell {
  uint64_t key;  // the grid point
  uint32_t vertex;
};

// Whether the distinct positions of `positions` round to distinct points of `grid` (the codec's rounding):
// groups (grid point, vertex) pairs by grid point and looks for a grid point whose vertices do not all share
// one position. With at most 20 bits per diagonal a grid coordinate fits in 21 bits, so a grid point packs
// into 63 bits. Equal grid points need only be adjacent, not ordered: one counting-sort pass into buckets of
// about 32 pairs by a hash of the grid point, then each bucket sorted in cache, buckets on every core.
// `cells` and `scratch` hold positions.size() entries. Cost: O(V) and about V log2(32) compares; no hash
// table (two hash sets over the positions cost 7 % of an elephant_1m bake) and no sort of all the pairs
// (elephant_5m: 0.23 s per bit count tried, three tried, against 0.08 s now).
bool separates(const std::vector<glm::vec3>& positions, const PositionGrid& grid, Cell* cells,
               Cell* scratch) {
  const size_t n = positions.size();
  if (n < 2) return true;
  const int bucket_bits = std::max(1, int(std::bit_width(n / 32)));
  const size_t buckets = size_t(1) << bucket_bits;
  auto bucket = [&](uint64_t key) { return size_t((key * 0x9E3779B97F4A7C15ull) >> (64 - bucket_bits)); };
  // The counting sort in kRuns runs of the pairs, on every core: each run computes its pairs' grid points
  // and counts its buckets, then scatters into its own slots of each bucket (the runs' counts prefixed
  // bucket by bucket, on one core: kRuns * buckets adds). elephant_5m's six passes under callgrind: one core
  // counted and scattered 273 M instructions; now the prefix is 31 M on one core, the count and scatter
  // (171 M) on every core; round_half_away for llround took separating() from 2,057 to 1,088 M in all.
  constexpr size_t kRuns = 8;
  std::vector<uint32_t> slot(kRuns * buckets, 0), start(buckets + 1);  // slot: by run, then bucket
  auto run_begin = [n](size_t r) { return n * r / kRuns; };
  tbb::parallel_for(size_t(0), kRuns, [&](size_t r) {
    uint32_t* count = &slot[r * buckets];
    for (size_t v = run_begin(r); v < run_begin(r + 1); ++v) {
      const glm::dvec3 t = (glm::dvec3(positions[v]) - glm::dvec3(grid.origin)) / double(grid.step);
      uint64_t key = 0;
      for (int a = 0; a < 3; ++a) key = key << 21 | (uint64_t(round_half_away(t[a])) & 0x1FFFFF);
      scratch[v] = {key, uint32_t(v)};
      ++count[bucket(key)];
    }
  });
  uint32_t filled = 0;
  for (size_t b = 0; b < buckets; ++b) {
    start[b] = filled;
    for (size_t r = 0; r < kRuns; ++r) filled += std::exchange(slot[r * buckets + b], filled);
  }
  start[buckets] = filled;
  tbb::parallel_for(size_t(0), kRuns, [&](size_t r) {
    uint32_t* next = &slot[r * buckets];
    for (size_t v = run_begin(r); v < run_begin(r + 1); ++v)
      cells[next[bucket(scratch[v].key)]++] = scratch[v];
  });
  std::atomic<bool> collision{false};
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, start.size() - 1, 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t b = r.begin(); b < r.end() && !collision.load(std::memory_order_relaxed); ++b) {
          Cell* const first = cells + start[b];
          Cell* const last = cells + start[b + 1];
          // Ties in any order: a grid point's vertices share one position iff all neighbours are equal.
          std::sort(first, last, [](const Cell& x, const Cell& y) { return x.key < y.key; });
          for (Cell* c = first + 1; c < last; ++c)
            if (c->key == c[-1].key && positions[c->vertex] != positions[c[-1].vertex]) collision = true;
        }
      });
  return !collision;
}

}  // namespace

PositionGrid PositionGrid::separating(const Mesh& mesh, int min_bits, int max_bits) {
  const Bounds bounds = mesh.bounds();
  // Arrays written in full before they are read are left uninitialized.
  const auto cells = std::make_unique_for_overwrite<Cell[]>(mesh.positions.size());
  const auto scratch = std::make_unique_for_overwrite<Cell[]>(mesh.positions.size());
  auto separating_grid = [&](double bits) {
    return separates(mesh.positions, for_bounds(bounds, bits), cells.get(), scratch.get());
  };
  int whole = min_bits;
  while (whole < max_bits && !separating_grid(whole)) ++whole;
  if (whole == min_bits) return for_bounds(bounds, whole);
  // whole - 1 bits collide, `whole` separate (or nothing below max_bits did): bisect the bit in between to
  // 2^-kFractionHalvings of a bit, keeping the coarsest grid tried that separates.
  double fine = whole, coarse = whole - 1;
  for (int i = 0; i < kFractionHalvings; ++i) {
    const double middle = 0.5 * (coarse + fine);
    (separating_grid(middle) ? fine : coarse) = middle;
  }
  return for_bounds(bounds, fine);
}

void PositionGrid::snap(Mesh& mesh) const {
  // The codec's formulas: q = round((p - origin) / step), decoded as origin + q * step (float). Positions
  // on every core (three double divisions each).
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.positions.size(), size_t(1) << 14),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t v = r.begin(); v < r.end(); ++v)
                        for (int a = 0; a < 3; ++a) {
                          float& x = mesh.positions[v][a];
                          x = origin[a] +
                              float(round_half_away((double(x) - double(origin[a])) / double(step))) * step;
                        }
                    });
  size_t kept = 0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    const glm::vec3 &pa = mesh.positions[a], &pb = mesh.positions[b], &pc = mesh.positions[c];
    if (pa == pb || pb == pc || pc == pa) continue;
    mesh.indices[kept++] = a, mesh.indices[kept++] = b, mesh.indices[kept++] = c;
  }
  mesh.indices.resize(kept);
}

int PositionGrid::bits(const Bounds& bounds) const {
  const float diagonal = bounds.diagonal();
  return diagonal > 0.0f ? int(std::lround(std::log2(double(diagonal) / double(step)))) : 0;
}

}  // namespace lodstream::package
