// The collapse loop's order (cost_order.hpp): both sorts give std::stable_sort's order by cost, ties (which
// decide the collapse order on flat regions) in input order, so the simplifier's output does not depend on
// which one a pass's size picks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "simplify/cost_order.hpp"

using namespace lodstream::simplify;

namespace {

// n candidates with costs among `distinct` values spread over many binades (so every radix digit matters),
// slots numbered in input order.
UninitializedVector<Ranked> random_candidates(size_t n, uint32_t distinct, std::mt19937& rng) {
  std::vector<float> values(distinct);
  std::uniform_real_distribution<float> mantissa(1.0f, 2.0f);
  std::uniform_int_distribution<int> exponent(-40, 20);
  for (float& v : values) v = std::ldexp(mantissa(rng), exponent(rng));
  values[0] = 0.0f;
  std::uniform_int_distribution<uint32_t> pick(0, distinct - 1);
  UninitializedVector<Ranked> items(n);
  for (uint32_t i = 0; i < n; ++i) items[i] = {values[pick(rng)], i};
  return items;
}

std::vector<uint32_t> slots(const UninitializedVector<Ranked>& items) {
  std::vector<uint32_t> s;
  for (const Ranked& r : items) s.push_back(r.slot);
  return s;
}

}  // namespace

TEST(CostOrder, BothSortsGiveTheStableOrder) {
  std::mt19937 rng(7);
  for (size_t n :
       {size_t(0), size_t(1), size_t(2), size_t(100), kSmallCostSort, kSmallCostSort + 1, size_t(70000)}) {
    for (uint32_t distinct : {1u, 3u, 50u, 100000u}) {
      const UninitializedVector<Ranked> input = random_candidates(n, distinct, rng);
      UninitializedVector<Ranked> expected = input;
      std::stable_sort(expected.begin(), expected.end(),
                       [](const Ranked& x, const Ranked& y) { return x.cost < y.cost; });
      for (size_t small : {size_t(0), n}) {  // the radix sort, then the comparison sort
        UninitializedVector<Ranked> items = input, scratch;
        std::vector<uint64_t> keys;
        sort_by_cost(items, scratch, keys, small);
        EXPECT_EQ(slots(items), slots(expected))
            << "n " << n << ", " << distinct << " costs, small " << small;
      }
    }
  }
}
