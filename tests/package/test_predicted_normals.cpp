// Normals coded in the frame of their prediction (predicted_normals.hpp): what the decoder rebuilds from the
// codes, in any frame (degenerate and seam predictions included), and the encoder's choice of the plain or
// the smoothed prediction; closed vertices' normals derived (derived_normals.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <random>
#include <tuple>

#include "core/mesh.hpp"
#include "package/byte_planes.hpp"
#include "package/derived_normals.hpp"
#include "package/predicted_normals.hpp"
#include "package/traversal_codec.hpp"
#include "support/shapes.hpp"

namespace lodstream::test {
namespace {

using namespace package;

double angle(glm::vec3 a, glm::vec3 b) {
  const glm::dvec3 x(a), y(b);
  return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y));
}

// The encoder's codes of `normals` (in their own order) against `sum`, and their plane width.
std::vector<uint64_t> encode(std::span<const glm::vec3> normals, std::span<const NormalSum> sum,
                             uint32_t bits, uint32_t& width) {
  std::vector<uint32_t> order(normals.size());
  std::iota(order.begin(), order.end(), 0u);
  return normal_residuals(normals, order, sum, bits, width);
}

// The decoder's normals from the encoder's codes against `sum`.
std::vector<glm::vec3> round_trip(std::span<const glm::vec3> normals, std::span<const NormalSum> sum,
                                  uint32_t bits) {
  uint32_t width = 0;
  const std::vector<uint64_t> codes = encode(normals, sum, bits, width);
  std::vector<uint8_t> planes;
  put_planes(planes, codes, 2, width);
  std::vector<glm::vec3> decoded;
  decode_predicted_normals(sum, uint32_t(normals.size()), planes.data(), width, bits, decoded);
  return decoded;
}

TEST(PredictedNormals, EveryNormalComesBackInAnyFrame) {
  // Random normals against random predictions (so the codes cover the whole sphere), and predictions at the
  // frame's seam (z = +-0), at its poles, zero, tiny, huge, infinite and NaN sums (the +z frame).
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  const NormalSum special[] = {{0, 0, 0, 0},   {1, 0, 0, 0},        {0, 1, -0.0f, 0},     {0, 0, -1, 0},
                               {0, 0, 1, 0},   {1e-30f, 0, 0, 0},   {3e38f, 3e38f, 1, 0}, {INFINITY, 0, 0},
                               {NAN, 0, 1, 0}, {-1, -1, -1e-30f, 0}};
  for (uint32_t bits : {8u, 9u, 12u, 16u}) {
    const size_t V = 4003;  // not a multiple of 4
    std::vector<glm::vec3> normals(V);
    std::vector<NormalSum> sum((V + 3) & ~size_t(3), NormalSum{0, 0, 0, 0});
    for (size_t v = 0; v < V; ++v) {
      normals[v] = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
      sum[v] = v % 5 == 0 ? special[(v / 5) % std::size(special)] : NormalSum{g(rng), g(rng), g(rng), 0};
    }
    const std::vector<glm::vec3> decoded = round_trip(normals, sum, bits);
    ASSERT_EQ(decoded.size(), V);
    double worst = 0.0;
    for (size_t v = 0; v < V; ++v) {
      EXPECT_NEAR(glm::length(decoded[v]), 1.0f, 1e-5f) << v;
      worst = std::max(worst, angle(decoded[v], normals[v]));
    }
    // The frame's codes are 1 / 0.52 (at 9 bits 1 / 0.49) times as wide as the global b-bit code's, whose
    // rounding errs by less than 5 * 2^-bits radians (test_codec's Octahedral test); the encoder's dead zone
    // errs by up to 1 - offset code steps instead of 1/2 (offset 0.4 below 9 bits, 0.2 at 9, 0.5 above).
    const double dead_zone = bits > 9 ? 1.0 : bits == 9 ? 1.6 : 1.2;
    EXPECT_LT(worst, dead_zone * std::ldexp(5.0 / (bits == 9 ? 0.49 : 0.52), -int(bits))) << bits << " bits";
    EXPECT_GT(worst, std::ldexp(0.5, -int(bits))) << bits << " bits";  // and the precision is really that
  }
}

TEST(PredictedNormals, WideLanesDecodeTheBitsOfFour) {
  // decode_predicted_normals takes four steps of 16 (AVX-512), 8 (AVX2) or 4 vertices (the baseline build)
  // interleaved, then single steps of 16, 8 and 4 for the rest: each group of 4 decoded alone (4 lanes) gives
  // the same bits as within the whole (in a wide step, alone or interleaved), in every frame of the test
  // above, in the build this CPU runs and in the baseline one.
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  const uint32_t V = 92, bits = 9;  // 64 + 16 + 8 + 4, 2 x 32 + 3 x 8 + 4, 5 x 16 + 3 x 4
  std::vector<NormalSum> sum(V);
  std::vector<glm::vec3> normals(V);
  for (uint32_t v = 0; v < V; ++v) {
    sum[v] = v % 7 == 0 ? NormalSum{0, 0, -0.0f, 0} : NormalSum{g(rng), g(rng), g(rng), 0};
    normals[v] = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
  }
  uint32_t width = 0;
  const std::vector<uint64_t> codes = encode(normals, sum, bits, width);
  std::vector<uint8_t> planes;
  put_planes(planes, codes, 2, width);
  for (auto decode : {decode_predicted_normals, decode_predicted_normals_baseline}) {
    std::vector<glm::vec3> whole;
    decode(sum, V, planes.data(), width, bits, whole);
    for (uint32_t first = 0; first < V; first += 4) {
      const std::vector<uint64_t> group(codes.begin() + 2 * first, codes.begin() + 2 * (first + 4));
      std::vector<uint8_t> group_planes;
      put_planes(group_planes, group, 2, width);
      std::vector<glm::vec3> alone;
      decode(std::span(sum).subspan(first, 4), 4, group_planes.data(), width, bits, alone);
      for (uint32_t v = 0; v < 4; ++v)
        for (int a = 0; a < 3; ++a)
          EXPECT_EQ(std::bit_cast<uint32_t>(alone[v][a]), std::bit_cast<uint32_t>(whole[first + v][a]))
              << first + v;
    }
  }
}

TEST(PredictedNormals, TheWidestBuildDecodesTheBaselineBits) {
  // decode_predicted_normals (on a CPU with AVX-512 its 16-lane build, else the 8-lane AVX2 one) gives the
  // baseline build's bits: random and degenerate sums (zero, tiny, huge, infinite, NaN, at the frame's seam),
  // with any codes (random planes, hostile ones included) of 1 to 3 bytes, at every count of the steps'
  // tails.
  std::mt19937 rng(11);
  std::normal_distribution<float> g;
  const NormalSum special[] = {
      {0, 0, 0, 0},   {0, 0, -0.0f, 0}, {1e-30f, 0, 0, 0},    {3e38f, 3e38f, 1, 0},   {INFINITY, 0, 0, 0},
      {NAN, 0, 1, 0}, {0, 0, -1, 0},    {-1, -1, -1e-30f, 0}, {1e-20f, 1e-20f, 0, 0}, {-INFINITY, 1, 0, 0}};
  size_t compared = 0;
  for (uint32_t V : {1u, 3u, 4u, 5u, 8u, 12u, 15u, 16u, 17u, 28u, 31u, 32u, 33u, 47u, 60u, 64u, 77u, 1001u})
    for (uint32_t width = 1; width <= 3; ++width)
      for (uint32_t bits : {8u, 9u, 12u}) {
        std::vector<NormalSum> sum((V + 3) & ~3u, NormalSum{0, 0, 0, 0});
        for (uint32_t v = 0; v < V; ++v)
          sum[v] = v % 3 == 0 ? special[(v / 3 + width) % std::size(special)]
                              : NormalSum{g(rng), g(rng), g(rng), 0} * float(1 << (v % 20));
        std::vector<uint8_t> planes(2 * width * V);
        for (uint8_t& b : planes) b = uint8_t(rng());
        std::vector<glm::vec3> widest, baseline;
        decode_predicted_normals(sum, V, planes.data(), width, bits, widest);
        decode_predicted_normals_baseline(sum, V, planes.data(), width, bits, baseline);
        ASSERT_EQ(widest.size(), V);
        ASSERT_EQ(baseline.size(), V);
        for (uint32_t v = 0; v < V; ++v)
          for (int a = 0; a < 3; ++a) {
            EXPECT_EQ(std::bit_cast<uint32_t>(widest[v][a]), std::bit_cast<uint32_t>(baseline[v][a]))
                << V << " vertices, " << width << " bytes, " << bits << " bits: vertex " << v;
            EXPECT_TRUE(std::isfinite(widest[v][a]));
          }
        compared += V;
      }
  EXPECT_GT(compared, 10000u);
}

TEST(PredictedNormals, AWellPredictedNormalStoresZeros) {
  // Normals equal to their (unnormalized) predictions code as (0, 0) in their frames, whatever their length.
  std::mt19937 rng(5);
  std::normal_distribution<float> g;
  std::vector<NormalSum> sum(64);
  std::vector<glm::vec3> normals(64);
  std::vector<uint32_t> order(64);
  std::iota(order.begin(), order.end(), 0u);
  for (size_t v = 0; v < 64; ++v) {
    sum[v] = NormalSum{g(rng), g(rng), g(rng), 0} * float(v + 1);
    normals[v] = glm::normalize(glm::vec3(sum[v][0], sum[v][1], sum[v][2]));
  }
  uint32_t width = 0;
  const std::vector<uint64_t> codes = normal_residuals(normals, order, sum, 9, width);
  EXPECT_EQ(width, 1u);
  for (uint64_t c : codes) EXPECT_EQ(c, 0u);
}

TEST(PredictedNormals, CodesRoundTowardThePredictionWithinADeadZone) {
  // Against the prediction +z the frame is the world's axes (t = +x, b = +y), so a normal (u, 0, 1 - u)
  // (octahedral coordinates (u, 0)) codes u * scale, rounded toward zero by the encoder's offset: 0.2 at 9
  // bits (scale 0.49 * 255), 0.4 at 8 (scale 0.52 * 127). Nearest rounding would code 1 and -1 for all four.
  for (const auto& [bits, scale, zero, one] :
       {std::tuple{9u, 0.49f * 255, 0.75f, 0.85f}, std::tuple{8u, 0.52f * 127, 0.55f, 0.65f}}) {
    std::vector<glm::vec3> normals;
    for (float x : {zero, one, -zero, -one})
      normals.push_back(glm::normalize(glm::vec3(x / scale, 0, 1 - std::abs(x) / scale)));
    std::vector<NormalSum> sum(4, NormalSum{0, 0, 1, 0});
    std::vector<uint32_t> order = {0, 1, 2, 3};
    uint32_t width = 0;
    const std::vector<uint64_t> codes = normal_residuals(normals, order, sum, bits, width);
    ASSERT_EQ(codes.size(), 8u);
    EXPECT_EQ(unzigzag(codes[0]), 0) << bits;
    EXPECT_EQ(unzigzag(codes[2]), 1) << bits;
    EXPECT_EQ(unzigzag(codes[4]), 0) << bits;
    EXPECT_EQ(unzigzag(codes[6]), -1) << bits;
    for (size_t v = 0; v < 4; ++v) EXPECT_EQ(codes[2 * v + 1], 0u) << bits;
  }
}

// code_normals on a mesh whose triangles the decoder sees as `m.indices`, over `positions`.
NormalCodes codes_of(const Mesh& m, const std::vector<glm::vec3>& positions, uint32_t bits) {
  std::vector<uint32_t> order(m.vertex_count());
  std::iota(order.begin(), order.end(), 0u);
  std::vector<glm::vec3> padded(positions);
  padded.push_back(glm::vec3(0.0f));  // predicted_normals reads one past the last
  return code_normals(m.normals, order, m.indices, 0, uint32_t(m.vertex_count()), padded.data(), bits);
}

uint64_t bits_of(const NormalCodes& c) {
  uint64_t b = 0;
  for (uint64_t code : c.codes) b += std::bit_width(code);
  return b;
}

TEST(PredictedNormals, TheEncoderSmoothsWhereQuantizedPositionsTiltTheFacesButNotAcrossACrease) {
  // A finely tessellated sphere with exact normals, its positions snapped to a coarse grid: each face is
  // tilted, the one-ring average much less.
  Mesh ball = sphere(1.0f, 96, 192);
  std::vector<glm::vec3> snapped = ball.positions;
  for (glm::vec3& p : snapped) p = glm::round(p * 256.0f) / 256.0f;
  const NormalCodes smooth_ball = codes_of(ball, snapped, 9);
  EXPECT_TRUE(smooth_ball.smooth);

  // A folded sheet (z = |x - 1/2|) whose normals are the plain prediction over its exact positions: the plain
  // prediction stores zeros, the smoothed one bends the normals along the crease.
  Mesh sheet = grid(16);
  for (glm::vec3& p : sheet.positions) p.z = std::abs(p.x - 0.5f);
  compute_smooth_normals(sheet);
  const NormalCodes plain_sheet = codes_of(sheet, sheet.positions, 9);
  EXPECT_FALSE(plain_sheet.smooth);
  EXPECT_EQ(bits_of(plain_sheet), 0u);
  std::vector<glm::vec3> padded(sheet.positions);
  padded.push_back(glm::vec3(0.0f));
  std::vector<NormalSum> smoothed;
  const uint32_t sheet_vertices = uint32_t(sheet.vertex_count());
  predicted_normals(sheet.indices, 0, sheet_vertices, padded.data(), sheet_vertices, true, smoothed);
  std::vector<uint32_t> order(sheet_vertices);
  std::iota(order.begin(), order.end(), 0u);
  uint32_t width = 0;
  const std::vector<uint64_t> bent = normal_residuals(sheet.normals, order, smoothed, 9, width);
  EXPECT_GT(std::count_if(bent.begin(), bent.end(), [](uint64_t c) { return c != 0; }), 16);

  // Both choices round-trip: the decoder rebuilds the prediction the node's flag names.
  for (const auto& [m, positions, codes] :
       {std::tuple(&ball, &snapped, &smooth_ball), std::tuple(&sheet, &sheet.positions, &plain_sheet)}) {
    std::vector<glm::vec3> padded(*positions);
    padded.push_back(glm::vec3(0.0f));
    std::vector<NormalSum> sum;
    const uint32_t V = uint32_t(m->vertex_count());
    predicted_normals(m->indices, 0, V, padded.data(), V, codes->smooth, sum);
    std::vector<uint8_t> planes;
    put_planes(planes, codes->codes, 2, codes->width);
    std::vector<glm::vec3> decoded;
    decode_predicted_normals(sum, V, planes.data(), codes->width, 9, decoded);
    for (uint32_t v = 0; v < V; ++v)
      EXPECT_LT(angle(decoded[v], glm::normalize(m->normals[v])), std::ldexp(5.0 / 0.49, -9)) << v;
  }
}

TEST(DerivedNormals, AFanIsClosedWhenEveryTriangleAroundTheVertexIsInTheNode) {
  std::vector<uint8_t> open;
  const Mesh ball = sphere(1.0f, 8, 16);
  const uint32_t V = uint32_t(ball.vertex_count());
  EXPECT_EQ(open_vertices(ball.indices, 0, V, open), 0u);  // closed and consistently oriented

  // A grid's fans are open on its boundary only.
  const Mesh sheet = grid(4);
  const uint32_t sheet_vertices = uint32_t(sheet.vertex_count());
  const uint32_t count = open_vertices(sheet.indices, 0, sheet_vertices, open);
  EXPECT_EQ(count, 16u);
  for (uint32_t v = 0; v < sheet_vertices; ++v) {
    const glm::vec3 p = sheet.positions[v];
    const bool border = p.x == 0.0f || p.x == 1.0f || p.y == 0.0f || p.y == 1.0f;
    EXPECT_EQ(open[v], border) << v;
  }

  // One triangle less opens its three corners' fans; so does a triangle reaching past the node (numbered
  // from first_vertex 100), which is not counted, and a vertex of no triangle is open.
  std::vector<uint32_t> holed(ball.indices.begin(), ball.indices.end() - 3);
  for (uint32_t& i : holed) i += 100;
  holed.insert(holed.end(), {100 + ball.indices[ball.indices.size() - 3], 100 + V, 100 + V + 1});
  EXPECT_EQ(open_vertices(holed, 100, V + 1, open), 4u);
  for (size_t k = ball.indices.size() - 3; k < ball.indices.size(); ++k) EXPECT_TRUE(open[ball.indices[k]]);
  EXPECT_TRUE(open[V]);
}

// A sphere whose normals are tilted off the surface's by about one code step at `bits` (1.15 step, with
// step = 1 / (scale (2^(bits - 1) - 1)) radians, scale 0.49 at 9 bits and 0.52 below: predicted_normals.cpp's
// frame_scale): without derivation the closed vertices would store codes of +-1 and decode off the
// prediction. The vertices (all closed) decode to their prediction, plain or smoothed (the encoder's choice),
// but for the few that the prediction's own error (the sphere's tessellation) puts more than a step off, and
// within three code steps of the normal given (both codes within 1.8 steps with the dead zone: 1.8 sqrt(2)
// = 2.55 steps apart at most).
void expect_closed_vertices_derived(uint32_t bits) {
  const double step = 1.0 / ((bits == 9 ? 0.49 : 0.52) * double((1 << (bits - 1)) - 1));
  Mesh ball = sphere(1.0f, 24, 48);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> turn(0.0f, 6.2831853f);
  for (glm::vec3& n : ball.normals) {
    const glm::vec3 t =
        glm::normalize(glm::cross(n, std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0)));
    const glm::vec3 b = glm::cross(n, t);
    const float a = turn(rng);
    n = glm::normalize(n + float(1.15 * step) * (std::cos(a) * t + std::sin(a) * b));
  }
  const PositionGrid grid = PositionGrid::for_bounds(ball.bounds(), 14);
  NodeGeometry g;
  g.mesh = &ball;
  g.normal_bits = bits;
  const TraversalCodec codec;
  const DecodedNode d = codec.decode(codec.encode(g, grid), grid, "derived");
  const uint32_t V = uint32_t(d.mesh.vertex_count());
  ASSERT_EQ(V, ball.vertex_count());

  std::vector<glm::vec3> padded(d.mesh.positions);
  padded.push_back(glm::vec3(0.0f));
  size_t at_prediction[2] = {0, 0};
  for (bool smooth : {false, true}) {
    std::vector<NormalSum> sum;
    predicted_normals(d.mesh.indices, 0, V, padded.data(), V, smooth, sum);
    for (uint32_t v = 0; v < V; ++v)
      at_prediction[smooth] += angle(d.mesh.normals[v], glm::vec3(sum[v][0], sum[v][1], sum[v][2])) < 1e-5;
  }
  EXPECT_GE(std::max(at_prediction[0], at_prediction[1]), V * 8 / 10) << bits << " bits";
  // (the codec renumbers the vertices: each decoded vertex is compared with the source's at its position)
  for (uint32_t v = 0; v < V; ++v) {
    uint32_t source = 0;
    for (uint32_t s = 1; s < V; ++s)
      if (glm::length(ball.positions[s] - d.mesh.positions[v]) <
          glm::length(ball.positions[source] - d.mesh.positions[v]))
        source = s;
    EXPECT_LT(angle(d.mesh.normals[v], ball.normals[source]), 3.0 * step) << bits << " bits, vertex " << v;
  }
}

TEST(DerivedNormals, ClosedVerticesWithinOneStepDecodeToThePrediction) {
  expect_closed_vertices_derived(kDerivedNormalBits);
}

// The coarse levels' normal bits (bake's --coarse-normal-bits 7, one less from 16 finest steps; 8 asked for)
// derive too.
TEST(DerivedNormals, CoarseNormalBitsDeriveToo) {
  expect_closed_vertices_derived(8);
  expect_closed_vertices_derived(7);
  expect_closed_vertices_derived(6);
}

}  // namespace
}  // namespace lodstream::test
