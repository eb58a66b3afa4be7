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

Sphere round_sphere_out(const Sphere& s, int grid_bits) {
  if (!(s.radius >= std::numeric_limits<float>::min()) || std::isinf(s.radius)) return s;
  const int exponent = std::ilogb(s.radius) - grid_bits;
  const double step = std::ldexp(1.0, exponent);
  Sphere out;
  for (int a = 0; a < 3; ++a) {
    const double k = std::nearbyint(double(s.center[a]) / step);
    if (!(std::abs(k) <= double(1 << 24))) return s;
    out.center[a] = float(k * step);  // exact: |k| <= 2^24
  }
  // r' >= r + |c' - c| + step, a multiple of the step (exact in float: r' / step < 2^(grid_bits + 2)).
  const double moved = glm::length(glm::dvec3(out.center) - glm::dvec3(s.center));
  out.radius = float(std::ceil((double(s.radius) + moved) / step + 1.0) * step);
  return sphere_contains(out, s, 0.0) ? out : s;
}

namespace {

using PairKey = std::array<uint32_t, 5>;
PairKey key(float error, const Sphere& s) {
  return {std::bit_cast<uint32_t>(error), std::bit_cast<uint32_t>(s.center.x),
          std::bit_cast<uint32_t>(s.center.y), std::bit_cast<uint32_t>(s.center.z),
          std::bit_cast<uint32_t>(s.radius)};
}

// The grids tried for a sphere, coarsest first: a finer one grows it less, so it fits where its parents'
// sphere is tight around it (the exact sphere always fits, the parents' rounded sphere being larger by a
// step), at a byte or two more.
// A pair of error 0 (a finest node's own) starts at kZeroErrorSphereGridBits.
constexpr int kGridBits[] = {kZeroErrorSphereGridBits, kSphereGridBits, kSphereGridBits + 3,
                             kSphereGridBits + 6, kSphereGridBits + 9};

struct PairGraph {
  std::vector<Sphere> exact, final;
  std::vector<std::vector<uint32_t>> parents;  // the pairs that are this pair's parents' pair somewhere
  std::vector<uint8_t> keep_exact, zero_error, state;  // state: 0 to do, 1 in progress, 2 done

  // final[p]: rounded on the coarsest grid of kGridBits whose rounded sphere lies inside every parents'
  // pair's final sphere, else exact. Parents' pairs are decided first (recursion depth: the number of
  // levels).
  void decide(uint32_t p) {
    state[p] = 1;
    for (uint32_t q : parents[p])
      if (state[q] == 0) decide(q);
    final[p] = exact[p];
    for (int bits : kGridBits) {
      if (keep_exact[p]) break;
      if (bits < kSphereGridBits && !zero_error[p]) continue;
      const Sphere s = round_sphere_out(exact[p], bits);
      bool inside = true;
      for (uint32_t q : parents[p])
        inside = inside && (q == p || (state[q] == 2 && sphere_contains(final[q], s, 0.0)));
      if (inside) {
        final[p] = s;
        break;
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
