// The builds of the predictive codecs' position decode (predictive_node.hpp, decode_predicted_vertices): the
// one this CPU runs, and the AVX2 one, give the baseline build's positions to the bit, and refuse the same
// nodes.
#include <gtest/gtest.h>

#include <bit>
#include <random>

#include "core/error.hpp"
#include "package/predictive_node.hpp"
#include "package/traversal_connectivity.hpp"

namespace lodstream::test {
namespace {

using namespace package;

using Build = void(const PredictiveNode&, std::span<const uint32_t>, const Parallelograms*,
                   const PositionGrid&, DecodedNode&, const std::string&);

void expect_baseline_bits(Build* build) {
  // `build` against the baseline build: random predictors below each vertex (or V: cmin), residual planes of
  // 1 to 5 bytes whose high bytes are zero, small or random (hostile: positions off the grid's range, which
  // both must refuse), every damping, with and without the plane and the multi-parallelogram prediction, at
  // counts around the vector steps' tails.
  std::mt19937 rng(7);
  const PositionGrid grid{glm::vec3(-1.5f, 0.25f, 3.0f), 0.001f};
  size_t compared = 0, wide_compared = 0, refused = 0;
  for (uint32_t V : {1u, 2u, 3u, 7u, 15u, 16u, 17u, 31u, 33u, 64u, 100u, 1001u})
    for (uint32_t width = 1; width <= 5; ++width)
      for (uint32_t high_mask : {0u, 3u, 63u, 255u})
        for (uint32_t damping = 2; damping <= 4; ++damping)
          for (int form = 0; form < 4; ++form) {
            const bool plane = form & 1, multi = form & 2;
            std::vector<uint8_t> planes(3 * size_t(width) * V);
            for (size_t i = 0; i < planes.size(); ++i)
              planes[i] = uint8_t(i < 3 * size_t(V) ? rng() : rng() & high_mask);
            // With high bytes masked to 63, the wide case: predictors among the first 8 vertices (those
            // predicted from cmin alone), so that coordinates spread over up to 2^31 stay in range (the plane
            // prediction's products then inexact in doubles).
            const bool wide = high_mask == 63;
            auto below = [&](uint32_t v) {
              if (wide) return v < 8 ? V : uint32_t(rng() % 8);
              return v == 0 || rng() % 16 == 0 ? V : uint32_t(rng() % v);
            };
            std::vector<uint32_t> predictors(3 * size_t(V));
            Parallelograms extra;
            extra.corners.resize(3 * size_t(V)), extra.found.resize(V);
            for (uint32_t v = 0; v < V; ++v) {
              for (int k = 0; k < 3; ++k)
                predictors[3 * v + k] = below(v), extra.corners[3 * v + k] = below(v);
              extra.found[v] = v > 0 && rng() % 2;
            }
            PredictiveNode p;
            p.vertices = V, p.index_end = V, p.position_bytes = width, p.damping = damping;
            p.flags = (plane ? kPlanePrediction : 0) | (multi ? kMultiParallelogram : 0);
            p.cmin[0] = 1000, p.cmin[1] = -7, p.cmin[2] = 123456;
            p.position_planes = planes;
            DecodedNode widest, baseline;
            bool widest_refused = false, baseline_refused = false;
            try {
              build(p, predictors, multi ? &extra : nullptr, grid, widest, "node");
            } catch (const Error&) {
              widest_refused = true;
            }
            try {
              decode_predicted_vertices_baseline(p, predictors, multi ? &extra : nullptr, grid, baseline,
                                                 "node");
            } catch (const Error&) {
              baseline_refused = true;
            }
            ASSERT_EQ(widest_refused, baseline_refused) << V << " vertices, " << width << " bytes";
            if (baseline_refused) {
              ++refused;
              continue;
            }
            ASSERT_EQ(widest.mesh.positions.size(), V);
            ASSERT_EQ(baseline.mesh.positions.size(), V);
            for (uint32_t v = 0; v < V; ++v)
              for (int a = 0; a < 3; ++a)
                ASSERT_EQ(std::bit_cast<uint32_t>(widest.mesh.positions[v][a]),
                          std::bit_cast<uint32_t>(baseline.mesh.positions[v][a]))
                    << V << " vertices, " << width << " bytes, damping " << damping << ", form " << form
                    << ": vertex " << v;
            compared += V, wide_compared += wide ? V : 0;
          }
  EXPECT_GT(compared, 100000u);
  EXPECT_GT(wide_compared, 10000u);
  EXPECT_GT(refused, 100u);
}

void expect_baseline_planes(Build* build) {
  // The plane prediction where the dominant axis is a tie or n = 0 (the AVX2 and AVX-512 builds take it from
  // a table indexed by the compares of |n|'s components, the baseline by selects): residuals in {-1, 0, 1}
  // around predictors among a few vertices, so that gates are small, often axis-aligned or degenerate
  // triangles.
  std::mt19937 rng(11);
  const PositionGrid grid{glm::vec3(0.0f), 0.01f};
  size_t ties = 0, flat = 0;
  for (uint32_t V : {5u, 64u, 1000u})
    for (uint32_t damping = 2; damping <= 4; ++damping) {
      std::vector<uint8_t> planes(3 * size_t(V));
      for (uint8_t& b : planes) b = uint8_t(rng() % 3);  // zigzag: 0, -1, 1
      std::vector<uint32_t> predictors(3 * size_t(V));
      for (uint32_t v = 0; v < V; ++v)
        for (int k = 0; k < 3; ++k) predictors[3 * v + k] = v < 4 ? V : uint32_t(rng() % 4);
      PredictiveNode p;
      p.vertices = V, p.index_end = V, p.position_bytes = 1, p.damping = damping, p.flags = kPlanePrediction;
      p.position_planes = planes;
      DecodedNode widest, baseline;
      build(p, predictors, nullptr, grid, widest, "node");
      decode_predicted_vertices_baseline(p, predictors, nullptr, grid, baseline, "node");
      ASSERT_EQ(widest.mesh.positions.size(), V);
      for (uint32_t v = 0; v < V; ++v) {
        for (int a = 0; a < 3; ++a)
          ASSERT_EQ(std::bit_cast<uint32_t>(widest.mesh.positions[v][a]),
                    std::bit_cast<uint32_t>(baseline.mesh.positions[v][a]))
              << V << " vertices, damping " << damping << ": vertex " << v;
        // The gate's normal from the decoded positions' coarse coordinates (small integers).
        const uint32_t* o = &predictors[3 * v];
        if (o[0] == V) continue;
        auto coarse = [&](uint32_t i) { return glm::round(glm::dvec3(baseline.mesh.positions[i]) / 0.01); };
        const glm::dvec3 m = glm::abs(glm::cross(coarse(o[0]) - coarse(o[2]), coarse(o[1]) - coarse(o[2])));
        flat += m == glm::dvec3(0.0);
        ties += m != glm::dvec3(0.0) && (m.x == m.y || m.y == m.z || m.x == m.z);
      }
    }
  EXPECT_GT(ties, 100u);
  EXPECT_GT(flat, 100u);
}

// decode_predicted_vertices: on a CPU with AVX-512 its x86-64-v4 build, else the AVX2 one.
TEST(PredictedVertices, TheWidestBuildDecodesTheBaselineBits) {
  expect_baseline_bits(decode_predicted_vertices);
}
TEST(PredictedVertices, TheWidestBuildDecodesTiedAndFlatPlanesAsTheBaseline) {
  expect_baseline_planes(decode_predicted_vertices);
}
// The AVX2 build, which CPUs with AVX-512 do not reach through decode_predicted_vertices.
TEST(PredictedVertices, TheAvx2BuildDecodesTheBaselineBits) {
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2";
  expect_baseline_bits(decode_predicted_vertices_avx2);
}
TEST(PredictedVertices, TheAvx2BuildDecodesTiedAndFlatPlanesAsTheBaseline) {
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2";
  expect_baseline_planes(decode_predicted_vertices_avx2);
}

}  // namespace
}  // namespace lodstream::test
