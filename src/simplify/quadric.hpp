// Garland-Heckbert quadrics with Hoppe's (1999) sparse attribute terms. Internal to src/simplify.
//
// A plane quadric accumulates w * (n.p + d)^2 as Q = (A, b, c): A = sum w n n^T, b = sum w d n, c = sum w
// d^2, so that Q(p) = p^T A p + 2 b.p + c (the book's Δ(x), digest §7.6.2). An attribute s interpolated
// linearly over a face as s(p) = g.p + d adds (g.p + d - s)^2 per unit area; minimising over s gives s* =
// (G.p + D) / W with G = sum area g, D = sum area d, W = sum area, and leaves the reduced position quadric A
// - G G^T / W, b - G D / W, c - D^2 / W (Hoppe 99, eq. 3 eliminated in closed form). p is relative to an
// origin near the quadric's planes (edge_collapse.cpp stores each vertex's relative to its input position):
// the terms then stay about W dist^2 instead of cancelling from about W, which float rounding would drown.
#pragma once

#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lodstream::simplify {

// Four floats in vector lanes (GCC's generic vectors; see Lanes below).
using FloatLanes = float __attribute__((vector_size(16)));

struct Quadric {
  float a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
  float b0 = 0, b1 = 0, b2 = 0;
  float c = 0;
  float w = 0;  // area (attribute weight W); boundary penalties do not add to it

  void add(const Quadric& q) {
    a00 += q.a00, a01 += q.a01, a02 += q.a02, a11 += q.a11, a12 += q.a12, a22 += q.a22;
    b0 += q.b0, b1 += q.b1, b2 += q.b2, c += q.c, w += q.w;
  }
  // Adds q, which is stored relative to an origin `d` away from this one's (see Reduced::add).
  inline void add_shifted(const Quadric& q, const glm::dvec3& d);
  // Adds weight * (n.p + d)^2 (n need not be unit: a gradient g with offset d adds (g.p + d)^2): each term
  // (weight x first factor) x second factor, as the scalar expressions a00 += weight * n.x * n.x, ..., c +=
  // weight * d * d would give them (the first eight in two float vectors: the same operations per lane, so
  // the same bits). nd: (n, d), as an AttributeTerm holds them.
  // (A constant d = 0 had GCC 12 zero lanes with vmovq xmm, xmm, which valgrind 3.19 cannot decode: the
  // empty asm hides the lanes' values.)
  void add_plane(const glm::vec3& n, float d, float weight) {
    FloatLanes nd{n.x, n.y, n.z, d};
#if defined(__SSE2__)
    asm("" : "+x"(nd));
#endif
    add_plane(nd, weight);
  }
  inline void add_plane(FloatLanes nd, float weight);
};

// Attribute part of one vertex's quadric: G (3) and D (1) per attribute channel, W shared (Quadric::w).
struct AttributeTerm {
  glm::vec3 g{0.0f};
  float d = 0.0f;
};

// Two doubles in vector lanes (GCC's generic vectors: SSE2 on x86-64, plain code elsewhere), like FloatLanes;
// four doubles (two SSE registers, one AVX register). Each lane computes what the scalar expression would,
// bit for bit: the same operations in the same order, and nothing fused into multiply-adds (x86-64's baseline
// has no FMA; a build with -mfma or for another target may contract the two differently, which test_quadric
// would show).
using Lanes = double __attribute__((vector_size(16)));
using WideLanes = double __attribute__((vector_size(32)));

// The two floats at `at` as a pair of doubles (exact). On x86-64 one 8-byte load and one cvtps2pd: GCC 12
// lowers the conversion of a generic 2-float vector into two scalar conversions and an unpack, and in the
// AVX2 clones that of four floats to four doubles into halves joined by vinsertf128 and split again by
// vpermpd (with the 4-float form, horse 0.1 callgrind: place 222.3 -> 220.8 M instructions).
inline Lanes widen(const void* at) {
#if defined(__SSE2__)
  return Lanes(_mm_cvtps_pd(_mm_castpd_ps(_mm_load_sd(static_cast<const double*>(at)))));
#else
  float f[2];
  std::memcpy(f, at, sizeof f);
  return Lanes{f[0], f[1]};
#endif
}

// The ten terms (a00, a01, a02, a11, a12, a22, b0, b1, b2, c) as five pairs of lanes, in that order (a
// Quadric's first ten floats), so that sums and scalings take five vector operations instead of ten.
struct Terms {
  Lanes p[5] = {};

  // A Quadric's ten terms, converted to double: five loads of two floats, one conversion each.
  static Terms of(const Quadric& q) {
    Terms t;
    const char* at = reinterpret_cast<const char*>(&q);
    for (int k = 0; k < 5; ++k) t.p[k] = widen(at + 8 * k);
    return t;
  }
  void add(const Terms& t) { p[0] += t.p[0], p[1] += t.p[1], p[2] += t.p[2], p[3] += t.p[3], p[4] += t.p[4]; }
  // this -= t * s.
  void subtract_scaled(const Terms& t, double s) {
    p[0] -= t.p[0] * s, p[1] -= t.p[1] * s, p[2] -= t.p[2] * s, p[3] -= t.p[3] * s, p[4] -= t.p[4] * s;
  }
};
static_assert(sizeof(Quadric) == 11 * sizeof(float));  // ten terms and w, in that order, unpadded

// Sums over attribute channels of G G^T, G D and D^2 (the terms Reduced::eliminate subtracts), as Terms:
// (xx, xy, xz, yy, yz, zz, xd, yd, zd, dd).
struct ChannelSums {
  Terms t;

  // Adds one channel of a merged pair of wedges: G = G_a + G_b, D = D_a + G_a.shift + D_b (a's term moved
  // to b's origin, `shift` further; Reduced::add).
  void add(const AttributeTerm& a, const AttributeTerm& b, const glm::dvec3& shift) {
    static_assert(sizeof(AttributeTerm) == 4 * sizeof(float));  // g, then d
    const char *at_a = reinterpret_cast<const char*>(&a), *at_b = reinterpret_cast<const char*>(&b);
    const Lanes a_xy = widen(at_a), a_zd = widen(at_a + 8), b_xy = widen(at_b), b_zd = widen(at_b + 8);
    const Lanes xy = a_xy + b_xy, shifted = a_xy * Lanes{shift.x, shift.y};
    const double z = a_zd[0] + b_zd[0], d = a_zd[1] + (shifted[0] + shifted[1] + a_zd[0] * shift.z) + b_zd[1];
    add(xy, z, d);
  }

 private:
  // Adds G G^T, G D and D^2 for G = (xy, z).
  void add(const Lanes& xy, double z, double d) {
    const Lanes zd{z, d};
    t.p[0] += xy[0] * xy;            // xx, xy
    t.p[1] += xy * Lanes{z, xy[1]};  // xz, yy
    t.p[2] += Lanes{xy[1], z} * z;   // yz, zz
    t.p[3] += xy * d;                // xd, yd
    t.p[4] += zd * d;                // zd, dd
  }
};

// Symmetric 3x3 system in double precision, accumulated from quadrics and attribute reductions: the terms
// (a00, a01, a02, a11, a12, a22, b0, b1, b2, c) in pairs of lanes (Terms).
struct Reduced {
  Terms t;

  double a00() const { return t.p[0][0]; }
  double a01() const { return t.p[0][1]; }
  double a02() const { return t.p[1][0]; }
  double a11() const { return t.p[1][1]; }
  double a12() const { return t.p[2][0]; }
  double a22() const { return t.p[2][1]; }
  double b0() const { return t.p[3][0]; }
  double b1() const { return t.p[3][1]; }
  double b2() const { return t.p[4][0]; }
  double c() const { return t.p[4][1]; }

  void add(const Quadric& q) { t.add(Terms::of(q)); }
  void add(const Reduced& r) { t.add(r.t); }
  // Adds q stored relative to origin o_q, this one being relative to o = o_q + d: with y = p - o_q = y' + d,
  // Q = y'^T A y' + 2 (b + A d).y' + (c + 2 b.d + d^T A d). In lanes: (A d)_0, (A d)_1 in one pair,
  // (A d)_2 with b.d in another.
  void add(const Quadric& q, const glm::dvec3& d) {
    const Terms s = Terms::of(q);
    const Lanes &q0 = s.p[0], &q1 = s.p[1], &q2 = s.p[2], &q3 = s.p[3], &q4 = s.p[4];
    // (a00, a01) dx + (a01, a11) dy + (a02, a12) dz; (a02, b0) dx + (a12, b1) dy + (a22, b2) dz.
    const Lanes ad01 = q0 * d.x + Lanes{q0[1], q1[1]} * d.y + Lanes{q1[0], q2[0]} * d.z;
    const Lanes ad2_bd = Lanes{q1[0], q3[0]} * d.x + Lanes{q2[0], q3[1]} * d.y + Lanes{q2[1], q4[0]} * d.z;
    const double ad0 = ad01[0], ad1 = ad01[1], ad2 = ad2_bd[0], bd = ad2_bd[1];
    t.p[0] += q0, t.p[1] += q1, t.p[2] += q2;
    t.p[3] += q3 + ad01;
    t.p[4] += Lanes{q4[0] + ad2, q4[1] + 2 * bd + ad0 * d.x + ad1 * d.y + ad2 * d.z};
  }
  // Subtracts sum_j (G_j G_j^T, G_j D_j, D_j^2) / W over the attribute channels summed in `s` (the
  // closed-form minimum over each s_j): one division and one scaling for all channels.
  void eliminate(const ChannelSums& s, double w) { t.subtract_scaled(s.t, 1.0 / w); }
  // Q(p) = p^T A p + 2 b.p + c, clamped at 0 (rounding).
  [[gnu::always_inline]] double eval(const glm::dvec3& p) const { return clamped(unclamped(p)); }
  [[gnu::always_inline]] double unclamped(const glm::dvec3& p) const {
    return a00() * p.x * p.x + a11() * p.y * p.y + a22() * p.z * p.z +
           2 * (a01() * p.x * p.y + a02() * p.x * p.z + a12() * p.y * p.z) +
           2 * (b0() * p.x + b1() * p.y + b2() * p.z) + c();
  }
  static double clamped(double q) { return q > 0 ? q : 0; }
  // Optimal placement: solves A x = -b by Cramer's rule; false when A is ill-conditioned
  // (|det| below 1e-6 of the cube of its mean diagonal). Always inlined: GCC 12 left it a call from
  // place_with<3> (refined_elephant 0.1 callgrind: place_with<3> 159.8 M + solve 31.2 M; inlined, 169.9 M).
  [[gnu::always_inline]] bool solve(glm::dvec3& x) const {
    const double a00 = this->a00(), a01 = this->a01(), a02 = this->a02(), a11 = this->a11(),
                 a12 = this->a12(), a22 = this->a22(), b0 = this->b0(), b1 = this->b1(), b2 = this->b2();
    double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22, c02 = a01 * a12 - a02 * a11;
    double det = a00 * c00 + a01 * c01 + a02 * c02;
    double s = (a00 + a11 + a22) / 3.0;
    if (!(std::fabs(det) > 1e-6 * s * s * s) || s <= 0) return false;
    double c11 = a00 * a22 - a02 * a02, c12 = a01 * a02 - a00 * a12, c22 = a00 * a11 - a01 * a01;
    double inv = -1.0 / det;
    x.x = (c00 * b0 + c01 * b1 + c02 * b2) * inv;
    x.y = (c01 * b0 + c11 * b1 + c12 * b2) * inv;
    x.z = (c02 * b0 + c12 * b1 + c22 * b2) * inv;
    return std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z);
  }
  // Q along the line p + t e: Q(p + t e) = Q(p) + 2 t g + t^2 den with g = e^T A p + b.e and den = e^T A e
  // (digest §7.6.2), so that one evaluation at p and these two give Q anywhere on the segment.
  struct Line {
    double g, den;
    // The minimum's parameter on the segment, t in [0, 1]: t* = -g / den (0.5 where den is not positive).
    double parameter() const {
      if (!(den > 0)) return 0.5;
      const double t = -g / den;
      return t < 0 ? 0 : (t > 1 ? 1 : t);
    }
    // Q(p + t e) from q_p = Q(p) unclamped, clamped at 0 as eval: 4 operations.
    double at(double q_p, double t) const { return clamped(q_p + t * (2 * g + t * den)); }
  };
  // Always inlined: GCC 12 left segment_parameter (the same terms) a call from place after an unrelated
  // change (elephant_1m 0.1 callgrind, that build: place 3,225.9 M + segment_parameter 91.3 M; inlined,
  // 3,297.1 M).
  [[gnu::always_inline]] Line line(const glm::dvec3& p, const glm::dvec3& e) const {
    const glm::dvec3 ae{a00() * e.x + a01() * e.y + a02() * e.z, a01() * e.x + a11() * e.y + a12() * e.z,
                        a02() * e.x + a12() * e.y + a22() * e.z};
    return {glm::dot(p, ae) + b0() * e.x + b1() * e.y + b2() * e.z, glm::dot(e, ae)};
  }
  // Minimum along the segment p + t e, t in [0,1] (Line::parameter).
  [[gnu::always_inline]] double segment_parameter(const glm::dvec3& p, const glm::dvec3& e) const {
    return line(p, e).parameter();
  }
};

void Quadric::add_plane(FloatLanes nd, float weight) {
  // (a00, a01, a02, a11) += (w nx) (nx, ny, nz, ny); (a12, a22, b0, b1) += (w ny, w nz, w d, w d) (nz, nz,
  // nx, ny); b2 += (w d) nz; c += (w d) d. The lanes are shuffles of nd (one instruction each).
  char* at = reinterpret_cast<char*>(this);  // a00, then a12 16 bytes on
  FloatLanes lo, hi;
  std::memcpy(&lo, at, sizeof lo), std::memcpy(&hi, at + 16, sizeof hi);
  lo += weight * __builtin_shufflevector(nd, nd, 0, 0, 0, 1) * __builtin_shufflevector(nd, nd, 0, 1, 2, 1);
  hi += weight * __builtin_shufflevector(nd, nd, 1, 2, 3, 3) * __builtin_shufflevector(nd, nd, 2, 2, 0, 1);
  std::memcpy(at, &lo, sizeof lo), std::memcpy(at + 16, &hi, sizeof hi);
  b2 += weight * nd[3] * nd[2], c += weight * nd[3] * nd[3];
}

void Quadric::add_shifted(const Quadric& q, const glm::dvec3& d) {
  Reduced r;
  r.add(q, d);
  // Each term rounded to float, then added in float: four at a time, then b2 and c.
  const Lanes* t = r.t.p;
  for (int k = 0; k < 2; ++k) {
    char* at = reinterpret_cast<char*>(this) + 16 * k;
    FloatLanes f;
    std::memcpy(&f, at, sizeof f);
    f += __builtin_convertvector(__builtin_shufflevector(t[2 * k], t[2 * k + 1], 0, 1, 2, 3), FloatLanes);
    std::memcpy(at, &f, sizeof f);
  }
  b2 += float(t[4][0]), c += float(t[4][1]), w += q.w;
}

}  // namespace lodstream::simplify
