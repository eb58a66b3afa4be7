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
#include <glm/glm.hpp>

namespace lodstream::simplify {

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
  // Adds weight * (n.p + d)^2 (n need not be unit: a gradient g with offset d adds (g.p + d)^2).
  void add_plane(const glm::vec3& n, float d, float weight) {
    a00 += weight * n.x * n.x, a01 += weight * n.x * n.y, a02 += weight * n.x * n.z;
    a11 += weight * n.y * n.y, a12 += weight * n.y * n.z, a22 += weight * n.z * n.z;
    b0 += weight * d * n.x, b1 += weight * d * n.y, b2 += weight * d * n.z;
    c += weight * d * d;
  }
};

// Attribute part of one vertex's quadric: G (3) and D (1) per attribute channel, W shared (Quadric::w).
struct AttributeTerm {
  glm::vec3 g{0.0f};
  float d = 0.0f;
};

// Sums over attribute channels of G G^T, G D and D^2 (the terms Reduced::eliminate subtracts).
struct ChannelSums {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  double xd = 0, yd = 0, zd = 0;
  double dd = 0;

  void add(const glm::dvec3& g, double d) {
    xx += g.x * g.x, xy += g.x * g.y, xz += g.x * g.z, yy += g.y * g.y, yz += g.y * g.z, zz += g.z * g.z;
    xd += g.x * d, yd += g.y * d, zd += g.z * d;
    dd += d * d;
  }
};

// Symmetric 3x3 system in double precision, accumulated from quadrics and attribute reductions.
struct Reduced {
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
  double b0 = 0, b1 = 0, b2 = 0;
  double c = 0;

  // Adds a Quadric or a Reduced (same origin).
  template <class Q>
  void add(const Q& q) {
    a00 += q.a00, a01 += q.a01, a02 += q.a02, a11 += q.a11, a12 += q.a12, a22 += q.a22;
    b0 += q.b0, b1 += q.b1, b2 += q.b2, c += q.c;
  }
  // Adds q stored relative to origin o_q, this one being relative to o = o_q + d: with y = p - o_q = y' + d,
  // Q = y'^T A y' + 2 (b + A d).y' + (c + 2 b.d + d^T A d).
  void add(const Quadric& q, const glm::dvec3& d) {
    const double ad0 = q.a00 * d.x + q.a01 * d.y + q.a02 * d.z, ad1 = q.a01 * d.x + q.a11 * d.y + q.a12 * d.z,
                 ad2 = q.a02 * d.x + q.a12 * d.y + q.a22 * d.z;
    a00 += q.a00, a01 += q.a01, a02 += q.a02, a11 += q.a11, a12 += q.a12, a22 += q.a22;
    b0 += q.b0 + ad0, b1 += q.b1 + ad1, b2 += q.b2 + ad2;
    c += q.c + 2 * (double(q.b0) * d.x + double(q.b1) * d.y + double(q.b2) * d.z) + ad0 * d.x + ad1 * d.y +
         ad2 * d.z;
  }
  // Subtracts sum_j (G_j G_j^T, G_j D_j, D_j^2) / W over the attribute channels summed in `s` (the
  // closed-form minimum over each s_j): one division and one scaling for all channels.
  void eliminate(const ChannelSums& s, double w) {
    const double iw = 1.0 / w;
    a00 -= s.xx * iw, a01 -= s.xy * iw, a02 -= s.xz * iw, a11 -= s.yy * iw, a12 -= s.yz * iw,
        a22 -= s.zz * iw;
    b0 -= s.xd * iw, b1 -= s.yd * iw, b2 -= s.zd * iw;
    c -= s.dd * iw;
  }
  // Q(p) = p^T A p + 2 b.p + c, clamped at 0 (rounding).
  double eval(const glm::dvec3& p) const {
    double r = a00 * p.x * p.x + a11 * p.y * p.y + a22 * p.z * p.z +
               2 * (a01 * p.x * p.y + a02 * p.x * p.z + a12 * p.y * p.z) +
               2 * (b0 * p.x + b1 * p.y + b2 * p.z) + c;
    return r > 0 ? r : 0;
  }
  // Optimal placement: solves A x = -b by Cramer's rule; false when A is ill-conditioned
  // (|det| below 1e-6 of the cube of its mean diagonal).
  bool solve(glm::dvec3& x) const {
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
  // Minimum along the segment p + t e, t in [0,1] (digest §7.6.2: t* = -(e^T A p + b.e) / (e^T A e)).
  double segment_parameter(const glm::dvec3& p, const glm::dvec3& e) const {
    glm::dvec3 ae{a00 * e.x + a01 * e.y + a02 * e.z, a01 * e.x + a11 * e.y + a12 * e.z,
                  a02 * e.x + a12 * e.y + a22 * e.z};
    double den = glm::dot(e, ae);
    if (!(den > 0)) return 0.5;
    double t = -(glm::dot(p, ae) + b0 * e.x + b1 * e.y + b2 * e.z) / den;
    return t < 0 ? 0 : (t > 1 ? 1 : t);
  }
};

void Quadric::add_shifted(const Quadric& q, const glm::dvec3& d) {
  Reduced r;
  r.add(q, d);
  a00 += float(r.a00), a01 += float(r.a01), a02 += float(r.a02), a11 += float(r.a11), a12 += float(r.a12);
  a22 += float(r.a22), b0 += float(r.b0), b1 += float(r.b1), b2 += float(r.b2), c += float(r.c), w += q.w;
}

}  // namespace lodstream::simplify
