// Quadrics (quadric.hpp): the terms summed two per vector operation give, bit for bit, the scalar formulas
// the header documents (the simplifier's output depends on every bit of them), and a shifted quadric measures
// the same distances from its new origin.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "simplify/quadric.hpp"

using namespace lodstream::simplify;

namespace {

// A quadric of a few random planes and attribute gradients (area-weighted), as build_quadrics sums them.
Quadric random_quadric(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), w(0.01f, 2.0f);
  Quadric q;
  for (int i = 0; i < 5; ++i) {
    const glm::vec3 n = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0, 0, 2.5f));
    const float area = w(rng);
    q.add_plane(n, 0.1f * u(rng), area);
    q.add_plane(glm::vec3(u(rng), u(rng), u(rng)), u(rng), area);  // a gradient g with offset d
    q.w += area;
  }
  return q;
}

// The ten terms of a Reduced, in order.
std::array<double, 10> terms(const Reduced& r) {
  return {r.a00(), r.a01(), r.a02(), r.a11(), r.a12(), r.a22(), r.b0(), r.b1(), r.b2(), r.c()};
}

TEST(Quadric, ShiftedSumIsTheScalarFormulaBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (int trial = 0; trial < 200; ++trial) {
    const Quadric q = random_quadric(rng), q2 = random_quadric(rng);
    const glm::dvec3 d(u(rng), u(rng), u(rng));
    Reduced r;
    r.add(q2);
    r.add(q, d);
    // Reduced::add(q, d): A, b + A d, c + 2 b.d + d^T A d, each sum left to right, on top of q2's terms.
    const double a00 = q.a00, a01 = q.a01, a02 = q.a02, a11 = q.a11, a12 = q.a12, a22 = q.a22;
    const double ad0 = a00 * d.x + a01 * d.y + a02 * d.z, ad1 = a01 * d.x + a11 * d.y + a12 * d.z,
                 ad2 = a02 * d.x + a12 * d.y + a22 * d.z;
    const std::array<double, 10> expected = {
        double(q2.a00) + a00,
        double(q2.a01) + a01,
        double(q2.a02) + a02,
        double(q2.a11) + a11,
        double(q2.a12) + a12,
        double(q2.a22) + a22,
        double(q2.b0) + (double(q.b0) + ad0),
        double(q2.b1) + (double(q.b1) + ad1),
        double(q2.b2) + (double(q.b2) + ad2),
        double(q2.c) + (double(q.c) + 2 * (double(q.b0) * d.x + double(q.b1) * d.y + double(q.b2) * d.z) +
                        ad0 * d.x + ad1 * d.y + ad2 * d.z)};
    EXPECT_EQ(terms(r), expected) << "trial " << trial;

    // Quadric::add_shifted: each term rounded to float, then added in float.
    Quadric f = q2;
    f.add_shifted(q, d);
    Reduced shifted;
    shifted.add(q, d);
    const std::array<double, 10> s = terms(shifted);
    EXPECT_EQ(f.a00, q2.a00 + float(s[0]));
    EXPECT_EQ(f.a12, q2.a12 + float(s[4]));
    EXPECT_EQ(f.b1, q2.b1 + float(s[7]));
    EXPECT_EQ(f.b2, q2.b2 + float(s[8]));
    EXPECT_EQ(f.c, q2.c + float(s[9]));
    EXPECT_EQ(f.w, q2.w + q.w);

    // The shifted quadric measures from an origin d further: Q'(y') = Q(y' + d).
    Reduced plain;
    plain.add(q);
    const glm::dvec3 y(u(rng), u(rng), u(rng));
    EXPECT_NEAR(shifted.eval(y), plain.eval(y + d), 1e-12 * (1 + plain.eval(y + d)));
  }
}

TEST(Quadric, LineGivesTheQuadricAlongTheSegment) {
  // Reduced::Line (place's fallback): Q(p + t e) from Q(p), g and den agrees with an evaluation at the
  // point, for the ends, the midpoint and the parameter it picks, which is the minimum over [0, 1] where Q
  // is convex along the line; and segment_parameter is that parameter.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (int trial = 0; trial < 200; ++trial) {
    Reduced r;
    r.add(random_quadric(rng));
    const glm::dvec3 p(u(rng), u(rng), u(rng)), e(u(rng), u(rng), u(rng));
    const Reduced::Line l = r.line(p, e);
    const double q_p = r.unclamped(p), t_opt = l.parameter();
    EXPECT_EQ(t_opt, r.segment_parameter(p, e));
    const double scale = 1e-12 * (1 + r.eval(p) + r.eval(p + e));
    for (double t : {0.0, 0.5, 1.0, t_opt}) EXPECT_NEAR(l.at(q_p, t), r.eval(p + t * e), scale) << trial;
    if (l.den > 0) {  // a minimum: Q is convex along the line
      for (int k = 0; k <= 20; ++k) EXPECT_LE(l.at(q_p, t_opt), l.at(q_p, k / 20.0) + scale) << trial;
    }
  }
}

TEST(Quadric, PlaneIsTheScalarFormulaBitForBit) {
  // Quadric::add_plane (two float vectors and two scalars): each term (weight x first factor) x second
  // factor, added to the term before, as the header's scalar formulas; from a vec3 and d (d = 0 as for a
  // face's plane, or any), and from the (g, d) lanes as build_quadrics passes an AttributeTerm.
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), w(0.01f, 2.0f);
  for (int trial = 0; trial < 200; ++trial) {
    const Quadric q = random_quadric(rng);
    const glm::vec3 n(u(rng), u(rng), u(rng));
    const float d = trial % 2 ? 0.0f : u(rng), weight = w(rng);
    const float expected[10] = {q.a00 + weight * n.x * n.x, q.a01 + weight * n.x * n.y,
                                q.a02 + weight * n.x * n.z, q.a11 + weight * n.y * n.y,
                                q.a12 + weight * n.y * n.z, q.a22 + weight * n.z * n.z,
                                q.b0 + weight * d * n.x,    q.b1 + weight * d * n.y,
                                q.b2 + weight * d * n.z,    q.c + weight * d * d};
    Quadric from_vec3 = q, from_lanes = q;
    from_vec3.add_plane(n, d, weight);
    const AttributeTerm term{n, d};
    FloatLanes nd;
    std::memcpy(&nd, &term, sizeof nd);
    from_lanes.add_plane(nd, weight);
    for (const Quadric& got : {from_vec3, from_lanes}) {
      EXPECT_EQ(std::memcmp(&got, expected, sizeof expected), 0) << "trial " << trial;
      EXPECT_EQ(got.w, q.w);
    }
  }
}

TEST(Quadric, WidenConvertsTwoFloatsExactly) {
  // The pair conversion (one cvtps2pd on x86-64) gives what two scalar conversions give, bit for bit,
  // including zeros' signs, subnormals, infinities and the largest float; in either lane.
  const float values[] = {0.0f,          -0.0f,    1.0f,      -1.5f, 0x1p-149f, -0x1p-126f,
                          3.4028235e38f, INFINITY, -INFINITY, 0.1f,  1e-7f};
  for (float x : values)
    for (float y : values) {
      const float pair[2] = {x, y};
      const Lanes l = widen(pair);
      const double expected[2] = {double(x), double(y)}, got[2] = {l[0], l[1]};
      EXPECT_EQ(std::memcmp(got, expected, sizeof got), 0) << x << ", " << y;
    }
}

TEST(Quadric, EliminationIsTheScalarFormulaBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int trial = 0; trial < 200; ++trial) {
    const Quadric q = random_quadric(rng);
    const glm::dvec3 shift(0.01 * u(rng), 0.01 * u(rng), 0.01 * u(rng));
    std::array<AttributeTerm, 3> ta, tb;
    for (int j = 0; j < 3; ++j) {
      ta[j] = {glm::vec3(u(rng), u(rng), u(rng)), u(rng)};
      tb[j] = {glm::vec3(u(rng), u(rng), u(rng)), u(rng)};
    }
    ChannelSums sums;
    for (int j = 0; j < 3; ++j) sums.add(ta[j], tb[j], shift);
    Reduced r;
    r.add(q);
    const double w = 1.5;
    r.eliminate(sums, w);
    // G = G_a + G_b, D = D_a + G_a.shift + D_b per channel; subtract sum G G^T / W, G D / W, D^2 / W.
    double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0, xd = 0, yd = 0, zd = 0, dd = 0;
    for (int j = 0; j < 3; ++j) {
      const glm::dvec3 ga(ta[j].g), g = ga + glm::dvec3(tb[j].g);
      const double d = double(ta[j].d) + (ga.x * shift.x + ga.y * shift.y + ga.z * shift.z) + double(tb[j].d);
      xx += g.x * g.x, xy += g.x * g.y, xz += g.x * g.z, yy += g.y * g.y, yz += g.y * g.z, zz += g.z * g.z;
      xd += g.x * d, yd += g.y * d, zd += g.z * d, dd += d * d;
    }
    const double iw = 1.0 / w;
    const std::array<double, 10> expected = {
        double(q.a00) - xx * iw, double(q.a01) - xy * iw, double(q.a02) - xz * iw, double(q.a11) - yy * iw,
        double(q.a12) - yz * iw, double(q.a22) - zz * iw, double(q.b0) - xd * iw,  double(q.b1) - yd * iw,
        double(q.b2) - zd * iw,  double(q.c) - dd * iw};
    EXPECT_EQ(terms(r), expected) << "trial " << trial;
  }
}

}  // namespace
