#include "package/pair_rounding.hpp"

#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

namespace lodstream::package {

float round_error_up(float e) {
  const uint32_t bits = std::bit_cast<uint32_t>(e);
  if (!(e > 0.0f) || std::isinf(e) || (bits & 0xFFu) == 0) return e;
  const float up = std::bit_cast<float>((bits | 0xFFu) + 1u);  // next multiple of 2^8 in the bit pattern
  return std::isinf(up) ? e : up;
}

namespace {

// The sphere on the grid of step 2^(ilogb r - grid_bits) with its centre on the grid point `corner` of the
// cell around s's centre (bit a set: coordinate a rounded up, else down; -1: the nearest grid point) and
// radius r' = ceil((r + |c' - c|) / step + margin) steps, or `s` when it has no such grid. Cost: O(1).
Sphere round_on_grid(const Sphere& s, int grid_bits, int corner, int margin) {
  if (!(s.radius >= std::numeric_limits<float>::min()) || std::isinf(s.radius)) return s;
  const int exponent = std::ilogb(s.radius) - grid_bits;
  const double step = std::ldexp(1.0, exponent);
  Sphere out;
  for (int a = 0; a < 3; ++a) {
    const double v = double(s.center[a]) / step;
    const double k = corner < 0 ? std::nearbyint(v) : (corner >> a & 1) ? std::ceil(v) : std::floor(v);
    if (!(std::abs(k) <= double(1 << 24))) return s;
    out.center[a] = float(k * step);  // exact: |k| <= 2^24
  }
  // A multiple of the step, exact in float: r' / step < 2^(grid_bits + 2).
  const double moved = glm::length(glm::dvec3(out.center) - glm::dvec3(s.center));
  out.radius = float(std::ceil((double(s.radius) + moved) / step + margin) * step);
  return sphere_contains(out, s, 0.0) ? out : s;
}

}  // namespace

Sphere round_sphere_out(const Sphere& s, int grid_bits) {
  return round_on_grid(s, grid_bits, -1, 1);
}

namespace {

using PairKey = std::array<uint32_t, 5>;
PairKey key(float error, const Sphere& s) {
  return {std::bit_cast<uint32_t>(error), std::bit_cast<uint32_t>(s.center.x),
          std::bit_cast<uint32_t>(s.center.y), std::bit_cast<uint32_t>(s.center.z),
          std::bit_cast<uint32_t>(s.radius)};
}

// The grids tried for a sphere, coarsest first, each twice as fine as the one before (a finer one grows it
// less, so it fits where its parents' sphere is tight around it; the exact sphere always fits, the parents'
// rounded sphere being larger by a step), down to 2^-kFinestGridBits of the radius. A pair of error 0 (a
// finest node's own) starts at kZeroErrorSphereGridBits, any other at kSphereGridBits.
constexpr int kFinestGridBits = kSphereGridBits + 9;

struct PairGraph {
  std::vector<Sphere> exact, final;
  std::vector<std::vector<uint32_t>> parents;  // the pairs that are this pair's parents' pair somewhere
  std::vector<uint8_t> keep_exact, zero_error, state;  // state: 0 to do, 1 in progress, 2 done

  // final[p]: rounded on the coarsest grid whose rounded sphere lies inside every parents' pair's final
  // sphere, else exact. On a grid, the centre tried on the nearest grid point, then on each corner of the
  // grid cell around it, with one step of margin, then none (a sphere that does not fit its parents' on a
  // grid costs a bit more a coordinate and the radius on each finer grid: refined_elephant's index pages
  // 6,388 -> 6,015 B with every grid tried where grids 2^3 apart were, -> 5,743 B with the corners and no
  // margin). Parents' pairs are decided first (recursion depth: the
  // number of levels). Cost: at most 18 candidates a grid, each checked against every parents' pair.
  void decide(uint32_t p) {
    state[p] = 1;
    for (uint32_t q : parents[p])
      if (state[q] == 0) decide(q);
    final[p] = exact[p];
    auto fits = [&](const Sphere& s) {
      for (uint32_t q : parents[p])
        if (q != p && (state[q] != 2 || !sphere_contains(final[q], s, 0.0))) return false;
      return true;
    };
    const int coarsest = zero_error[p] ? kZeroErrorSphereGridBits : kSphereGridBits;
    for (int bits = coarsest; bits <= kFinestGridBits && !keep_exact[p]; ++bits) {
      for (int margin = 1; margin >= 0; --margin) {
        for (int corner = -1; corner < 8; ++corner) {
          const Sphere s = round_on_grid(exact[p], bits, corner, margin);
          if (fits(s)) {
            final[p] = s;
            state[p] = 2;
            return;
          }
        }
      }
    }
    state[p] = 2;
  }
};

}  // namespace

void round_pairs(std::span<NodeRecord> nodes) {
  PairGraph g;
  std::map<PairKey, uint32_t> ids;
  auto id = [&](float error, const Sphere& s) {
    const auto [it, added] = ids.try_emplace(key(error, s), uint32_t(g.exact.size()));
    if (added)
      g.exact.push_back(s), g.parents.emplace_back(), g.keep_exact.push_back(0),
          g.zero_error.push_back(error == 0.0f);
    return it->second;
  };
  std::vector<std::pair<uint32_t, uint32_t>> node_pairs(nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i) {
    const NodeRecord& n = nodes[i];
    const uint32_t own = id(n.error, n.sphere), parent = id(n.parent_error, n.parent_sphere);
    node_pairs[i] = {own, parent};
    if (n.parents.empty()) {
      g.keep_exact[own] = g.keep_exact[parent] = 1;
    } else {
      g.parents[own].push_back(parent);
    }
  }
  g.final.resize(g.exact.size());
  g.state.assign(g.exact.size(), 0);
  for (uint32_t p = 0; p < g.exact.size(); ++p)
    if (g.state[p] == 0) g.decide(p);
  for (size_t i = 0; i < nodes.size(); ++i) {
    NodeRecord& n = nodes[i];
    n.error = round_error_up(n.error), n.sphere = g.final[node_pairs[i].first];
    n.parent_error = round_error_up(n.parent_error), n.parent_sphere = g.final[node_pairs[i].second];
  }
}

}  // namespace lodstream::package
