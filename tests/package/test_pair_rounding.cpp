// Conservative rounding of (error, sphere) pairs (pair_rounding.hpp): errors only grow and stay monotonic,
// rounded spheres contain the exact ones, a node's sphere stays inside its parents' even when containment is
// tight, parents' pairs stay their parents' own pairs bit for bit, and roots keep their exact spheres.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>

#include "package/pair_rounding.hpp"

namespace lodstream::test {
namespace {

using namespace package;

TEST(PairRounding, ErrorsRoundUpMonotonicallyTo16Bits) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-30.0f, 30.0f);
  std::vector<float> errors = {0.0f, INFINITY, 1.0f, 0x1.fffffep127f, 1e-45f};
  for (int i = 0; i < 2000; ++i) errors.push_back(std::exp2(u(rng)));
  std::sort(errors.begin(), errors.end());
  float previous = 0.0f;
  for (float e : errors) {
    const float r = round_error_up(e);
    EXPECT_GE(r, e);
    EXPECT_GE(r, previous);  // monotonic: sorted errors stay sorted
    if (std::isfinite(e) && e < 0x1p127f) {
      EXPECT_EQ(std::bit_cast<uint32_t>(r) & 0xFFu, 0u) << e;
    }
    if (std::isnormal(e) && e < 0x1p127f) {
      EXPECT_LE(double(r) - double(e), double(e) * 0x1p-15) << e;
    }
    previous = r;
  }
  EXPECT_EQ(round_error_up(0.0f), 0.0f);
  EXPECT_EQ(round_error_up(INFINITY), INFINITY);
  EXPECT_EQ(round_error_up(0x1.fffffep127f), 0x1.fffffep127f);  // would round to infinity: kept
}

TEST(PairRounding, RoundedSpheresContainTheExactOnesAndGrowLittle) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    const float scale = std::exp2(20.0f * u(rng));
    const Sphere s{{u(rng) * 1000.0f, u(rng) * scale, u(rng)}, scale * (1.0f + u(rng) * 0.9f)};
    const Sphere r = round_sphere_out(s);
    EXPECT_TRUE(sphere_contains(r, s, 0.0));
    EXPECT_LE(r.radius, s.radius * (1.0f + 3.0f * std::exp2(-float(kSphereGridBits)) + 1e-6f));
  }
  // No grid: zero radius, infinite radius, a centre more than 2^24 steps out.
  const Sphere point{{1.0f, 2.0f, 3.0f}, 0.0f};
  EXPECT_EQ(round_sphere_out(point).radius, 0.0f);
  const Sphere far{{1e9f, 0.0f, 0.0f}, 1.0f};
  EXPECT_EQ(round_sphere_out(far).center.x, far.center.x);
  EXPECT_EQ(round_sphere_out(far).radius, far.radius);
}

// A chain of nested spheres, each 1e-4 of its parent's radius from touching it from inside (tighter than the
// coarsest grid's rounding), as a DAG's levels: node i's parents are node i - 1 (node 0 is the root), with
// two siblings per level sharing a pair.
std::vector<NodeRecord> nested(int levels) {
  std::vector<NodeRecord> nodes;
  Sphere parent{{0.3f, -0.7f, 1.1f}, 100.0f};
  float parent_error = 50.0f;
  for (int l = 0; l < levels; ++l) {
    const Sphere own = l == 0 ? parent
                              : Sphere{parent.center + glm::vec3(0.3699f, 0.0f, 0.0f) * parent.radius,
                                       parent.radius * 0.63f};  // 1e-4 of the parent radius from its boundary
    const float error = l == 0 ? parent_error : parent_error * 0.4f;
    for (int sibling = 0; sibling < 2; ++sibling) {
      NodeRecord n;
      n.error = error, n.sphere = own;
      if (l > 0) {
        n.parents = {uint32_t(nodes.size() - 1 - sibling)};
        n.parent_error = parent_error, n.parent_sphere = parent;
      } else {
        n.parent_sphere = own;  // a root: +infinity parents' error
      }
      nodes.push_back(n);
    }
    parent = own, parent_error = error;
  }
  return nodes;
}

TEST(PairRounding, APairOfErrorZeroIsRoundedOnTheCoarserGrid) {
  // Two finest nodes (error 0) under one parents' pair, and that parents' own node: the finest nodes' own
  // spheres on the grid of 2^(ilogb r - 2) (kZeroErrorSphereGridBits), the parents' on 2^(ilogb r -
  // kSphereGridBits); each contains its exact sphere and lies inside its parents'.
  std::vector<NodeRecord> nodes(3);
  const Sphere parents{{0.1234567f, -0.7654321f, 0.3141593f}, 0.9876543f};
  nodes[0].error = 0.01f, nodes[0].sphere = parents, nodes[0].children = {1, 2};
  nodes[0].parents = {7}, nodes[0].parent_error = 0.5f, nodes[0].parent_sphere = {{0.0f, 0.0f, 0.0f}, 4.0f};
  const Sphere exact[2] = {{{0.2345678f, -0.6543219f, 0.1111111f}, 0.4321987f},
                           {{-0.1357913f, -0.8642097f, 0.5f}, 0.3333333f}};
  for (int i = 1; i <= 2; ++i) {
    NodeRecord& n = nodes[size_t(i)];
    n.error = 0.0f, n.sphere = exact[i - 1], n.parents = {0};
    n.parent_error = nodes[0].error, n.parent_sphere = parents;
  }
  round_pairs(nodes);
  auto on_grid = [](const Sphere& s, int exponent) {
    for (int a = 0; a < 3; ++a)
      if (std::ldexp(double(s.center[a]), -exponent) !=
          std::floor(std::ldexp(double(s.center[a]), -exponent)))
        return false;
    return true;
  };
  for (int i = 1; i <= 2; ++i) {
    const NodeRecord& n = nodes[size_t(i)];
    EXPECT_TRUE(on_grid(n.sphere, std::ilogb(exact[i - 1].radius) - 2)) << i;  // a quarter of 2^ilogb r
    EXPECT_TRUE(sphere_contains(n.sphere, exact[i - 1], 0.0)) << i;
    EXPECT_TRUE(sphere_contains(n.parent_sphere, n.sphere, 0.0)) << i;
  }
  EXPECT_TRUE(on_grid(nodes[0].sphere, std::ilogb(parents.radius) - kSphereGridBits));
  EXPECT_FALSE(on_grid(nodes[0].sphere, std::ilogb(parents.radius) - kZeroErrorSphereGridBits));
}

TEST(PairRounding, ASphereThatDoesNotFitOnItsGridTriesTheCellsCornersThenTheNextGrid) {
  // A node whose sphere is `slack` inside its parents' rounded sphere: the nearest grid point with a step of
  // margin (round_sphere_out) leaves the parents' sphere on its coarsest grid, so the rounding takes a corner
  // of the grid cell or no margin there (slack 0.0065), else the next grid (slack 0.0015), not the grid 2^3
  // times finer that the rounding went to before (a few bits more a coordinate).
  const Sphere parents{{0.1234567f, -0.7654321f, 0.3141593f}, 0.9876543f};
  const Sphere rounded_parents = round_sphere_out(parents);
  const glm::vec3 direction = glm::normalize(glm::vec3(0.6f, -0.3f, 0.74f));
  const float radius = 0.4321987f;
  for (const auto [slack, grid_bits] :
       {std::pair{0.0065f, kSphereGridBits}, std::pair{0.0015f, kSphereGridBits + 1}}) {
    SCOPED_TRACE("slack " + std::to_string(slack));
    const Sphere exact{rounded_parents.center + direction * (rounded_parents.radius - radius - slack),
                       radius};
    ASSERT_FALSE(sphere_contains(rounded_parents, round_sphere_out(exact), 0.0));
    std::vector<NodeRecord> nodes(2);
    nodes[0].error = 0.01f, nodes[0].sphere = parents, nodes[0].children = {1};
    nodes[0].parents = {7}, nodes[0].parent_error = 0.5f, nodes[0].parent_sphere = {{0.0f, 0.0f, 0.0f}, 4.0f};
    nodes[1].error = 0.001f, nodes[1].sphere = exact, nodes[1].parents = {0};
    nodes[1].parent_error = nodes[0].error, nodes[1].parent_sphere = parents;
    round_pairs(nodes);
    const Sphere& s = nodes[1].sphere;
    const int exponent = std::ilogb(radius) - grid_bits;
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(std::ldexp(double(s.center[a]), -exponent),
                std::floor(std::ldexp(double(s.center[a]), -exponent)))
          << a;
    EXPECT_EQ(std::ldexp(double(s.radius), -exponent), std::floor(std::ldexp(double(s.radius), -exponent)));
    EXPECT_TRUE(sphere_contains(s, exact, 0.0));
    EXPECT_EQ(nodes[0].sphere.radius, rounded_parents.radius);
    EXPECT_TRUE(sphere_contains(nodes[1].parent_sphere, s, 0.0));
  }
}

TEST(PairRounding, TightlyNestedPairsKeepEveryInvariant) {
  const std::vector<NodeRecord> exact = nested(12);
  std::vector<NodeRecord> nodes = exact;
  round_pairs(nodes);
  size_t rounded = 0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    SCOPED_TRACE("node " + std::to_string(i));
    const NodeRecord& n = nodes[i];
    EXPECT_GE(n.error, exact[i].error);
    EXPECT_TRUE(sphere_contains(n.sphere, exact[i].sphere, 0.0));
    rounded += std::bit_cast<uint32_t>(n.sphere.radius) != std::bit_cast<uint32_t>(exact[i].sphere.radius);
    if (n.parents.empty()) {
      EXPECT_EQ(n.sphere.radius, exact[i].sphere.radius);  // roots keep their spheres
      EXPECT_EQ(n.sphere.center, exact[i].sphere.center);
      continue;
    }
    const NodeRecord& p = nodes[n.parents[0]];
    EXPECT_LE(n.error, n.parent_error);
    EXPECT_TRUE(sphere_contains(n.parent_sphere, n.sphere, 0.0));
    EXPECT_EQ(std::bit_cast<uint32_t>(p.error), std::bit_cast<uint32_t>(n.parent_error));
    EXPECT_EQ(std::bit_cast<uint32_t>(p.sphere.radius), std::bit_cast<uint32_t>(n.parent_sphere.radius));
    EXPECT_EQ(p.sphere.center, n.parent_sphere.center);
  }
  // Every pair but the root's is rounded (on a finer grid where containment is tight).
  EXPECT_EQ(rounded, nodes.size() - 2);
}

}  // namespace
}  // namespace lodstream::test
