// The finest grid of a representation (package/node_codec.hpp, PositionGrid): separating() spends the bits
// that keep distinct positions apart (within a cap), snap() moves positions to the points the codec decodes
// and drops the triangles that degenerate.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "package/node_codec.hpp"

using namespace lodstream;
using namespace lodstream::package;

namespace {

// Two triangles sharing an edge, in a box of diagonal ~1, plus a third triangle whose corner c sits `gap`
// from corner b.
Mesh with_gap(float gap) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1.0f + gap, 0.0f, 0.0f}};
  m.indices = {0, 1, 2, 2, 1, 3, 1, 4, 3};
  return m;
}

TEST(PositionGrid, SeparatingSpendsTheBitsThatKeepVerticesApart) {
  const Mesh far_apart = with_gap(0.3f);
  EXPECT_EQ(PositionGrid::separating(far_apart).bits(far_apart.bounds()), 14);
  // A gap of 2^-15.5 of the diagonal: 14 bits merge the two vertices, some count up to 20 keeps them apart.
  const Mesh close = with_gap(std::ldexp(1.0f, -15) * 0.7f);
  const PositionGrid g = PositionGrid::separating(close);
  EXPECT_GT(g.bits(close.bounds()), 14);
  EXPECT_LE(g.bits(close.bounds()), 20);
  Mesh snapped = close;
  g.snap(snapped);
  EXPECT_NE(snapped.positions[1], snapped.positions[4]);
  EXPECT_EQ(snapped.triangle_count(), 3u);
  // With a cap of 14 bits they cannot be separated: the cap is returned, and snap welds them and drops
  // the triangle between them.
  const PositionGrid capped = PositionGrid::separating(close, 14, 14);
  EXPECT_EQ(capped.bits(close.bounds()), 14);
  Mesh welded = close;
  capped.snap(welded);
  EXPECT_EQ(welded.positions[1], welded.positions[4]);
  EXPECT_EQ(welded.triangle_count(), 2u);
}

// Whether `g` (the codec's rounding) maps no two distinct positions of `m` to one point, checked with an
// ordered map.
bool separates_plainly(const Mesh& m, const PositionGrid& g) {
  std::map<std::array<long long, 3>, glm::vec3> seen;
  for (const glm::vec3& p : m.positions) {
    std::array<long long, 3> key;
    for (int a = 0; a < 3; ++a) key[a] = std::llround((double(p[a]) - double(g.origin[a])) / double(g.step));
    const auto [it, added] = seen.emplace(key, p);
    if (!added && it->second != p) return false;
  }
  return true;
}

// The fewest whole bits in [14, 20] whose grid separates `m`, 20 when none does.
int reference_whole_bits(const Mesh& m) {
  for (int bits = 14; bits < 20; ++bits)
    if (separates_plainly(m, PositionGrid::for_bounds(m.bounds(), bits))) return bits;
  return 20;
}

TEST(PositionGrid, SeparatingOnALargeMeshMatchesAPlainCheck) {
  // A 300 x 300 grid of vertices (many buckets, every core), every fifth position repeated by a second
  // vertex (seams: equal positions never count as a collision), and one vertex `gap` beside another.
  std::vector<int> whole_bits;
  std::vector<double> found_bits;
  for (const float gap : {0.3f, 2e-5f, 1e-7f}) {
    Mesh m;
    constexpr int kSide = 300;
    for (int y = 0; y < kSide; ++y)
      for (int x = 0; x < kSide; ++x) m.positions.push_back({x / float(kSide), y / float(kSide), 0.01f * x});
    for (size_t v = 0; v < size_t(kSide) * kSide; v += 5) m.positions.push_back(m.positions[v]);
    m.positions.push_back(m.positions[4321] + glm::vec3(gap, 0.0f, 0.0f));
    const int whole = reference_whole_bits(m);
    const PositionGrid g = PositionGrid::separating(m);
    const double bits = std::log2(double(m.bounds().diagonal()) / double(g.step));
    // Never finer than the fewest whole bits, never coarser than the whole bit below them, and where some
    // grid separates, the one returned does.
    EXPECT_LE(bits, whole + 1e-6) << "gap " << gap;
    EXPECT_GE(bits, whole == 14 ? 14 - 1e-6 : whole - 1 + 0.125 - 1e-6) << "gap " << gap;
    if (whole < 20) {
      EXPECT_TRUE(separates_plainly(m, g)) << "gap " << gap;
    }
    whole_bits.push_back(whole);
    found_bits.push_back(bits);
  }
  // The cases span the range: no collision at 14 bits, one that needs more, one that no count separates.
  EXPECT_EQ(whole_bits, (std::vector<int>{14, whole_bits[1], 20}));
  EXPECT_GT(whole_bits[1], 14);
  EXPECT_LT(whole_bits[1], 20);
  // The one that needs more separates on a fraction of a bit less than whole bits would spend.
  EXPECT_LT(found_bits[1], whole_bits[1] - 0.1);
}

TEST(PositionGrid, SnappedPositionsAreWhatTheCodecDecodes) {
  Mesh m = with_gap(0.123456f);
  for (glm::vec3& p : m.positions) p = p * 37.1f + glm::vec3(-5.3f, 2.2f, 0.7f);
  const PositionGrid g = PositionGrid::separating(m);
  g.snap(m);
  NodeGeometry geometry;
  geometry.mesh = &m;
  const NodeCodec& codec = default_node_codec();
  const DecodedNode d = codec.decode(codec.encode(geometry, g), g, "test");
  ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
  std::vector<glm::vec3> a = m.positions, b = d.mesh.positions;
  auto less = [](const glm::vec3& x, const glm::vec3& y) {
    return std::tie(x.x, x.y, x.z) < std::tie(y.x, y.y, y.z);
  };
  std::sort(a.begin(), a.end(), less);
  std::sort(b.begin(), b.end(), less);
  EXPECT_EQ(a, b) << "decoding a snapped mesh gives its positions bit for bit";
}

// round_half_away (inline, used by separating() and snap() in place of libm's llround and round) rounds as
// std::llround does: halves away from zero, just below and above them, past 2^52 where every double is whole.
TEST(PositionGrid, RoundHalfAwayMatchesLibm) {
  std::vector<double> xs = {0.0,
                            -0.0,
                            0.5,
                            -0.5,
                            1.5,
                            -1.5,
                            2.5,
                            -2.5,
                            1048575.5,
                            0x1p52 + 1.0,
                            -0x1p52 - 1.0,
                            0x1p61 + 0x1p10,
                            0.49999999999999994};
  for (double h = 0.5; h < 3e6; h = h * 3.0 + 1.0)
    for (double x : {h, std::nextafter(h, 0.0), std::nextafter(h, 1e9)}) xs.push_back(x), xs.push_back(-x);
  for (double x : xs) EXPECT_EQ(round_half_away(x), std::llround(x)) << x;
}

}  // namespace
