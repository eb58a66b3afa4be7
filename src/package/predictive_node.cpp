#include "package/predictive_node.hpp"

#include <immintrin.h>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <type_traits>

#include "core/error.hpp"
#include "package/byte_planes.hpp"
#include "package/bytes.hpp"
#include "package/derived_normals.hpp"
#include "package/predicted_normals.hpp"
#include "package/scratch.hpp"
#include "package/vertex_attributes.hpp"
#include "package/widest_build.hpp"

namespace lodstream::package {

namespace {

constexpr uint32_t kMaxPositionBytes = 5, kMaxNormalBytes = 3;
// The encoder takes the multi-parallelogram prediction (predictive_node.hpp) only when its residuals' bit
// lengths add up to at least 3/4 bit a vertex fewer than the best single-parallelogram choice: it costs the
// decoder about 110 instructions a vertex (the traversal's joins, the second parallelogram and normal).
// Measured (`lodstream bake`, `bench decode --runs 1` under callgrind), threshold 0 / 1/2 / 3/4 / 1 bit:
// refined_elephant 271,148 B -> 259,949 / 260,780 / 261,306 / 262,722, elephant_1m 2,972,234 -> 2,892,577
// / 2,937,462 / unchanged / unchanged, elephant_1m's decode 1,188.9 M instructions -> 1,322.9 / 1,244.8 /
// unchanged (no node takes it).
constexpr uint64_t kMultiMinSavedBits = 3;  // quarter bits a vertex
// Decoded coarse coordinates stay within ±2^32 (valid ones within ±2^31), so no chain of predictions from
// hostile residuals (< 2^40) overflows int64.
constexpr int64_t kMaxCoarse = int64_t(1) << 32;

// The damped parallelogram P of predictive_node.hpp, wrapping (uint64) until the final arithmetic shift, so
// that hostile coordinates never overflow; j = 4 takes the plain form. The decoder calls it with j a
// template constant (predict_positions), the encoder with each j it tries.
inline uint64_t damped_parallelogram(uint64_t a, uint64_t b, uint64_t c, uint32_t j) {
  if (j == 4) return a + b - c;
  return uint64_t(int64_t((4 + j) * (a + b) - 2 * j * c + 4) >> 3);
}

// The multi-parallelogram P of predictive_node.hpp from vertex v's predictors o and second parallelogram
// `more` (3 entries each): per axis floor((sum over the two of (4 + j)(c[x] + c[y]) - 2j c[o]) + 8) / 16),
// wrapping until the final arithmetic shift, so that hostile coordinates never overflow; without `more`
// (null: no second parallelogram found) the damped_parallelogram of o alone, which the average of o with
// itself equals for valid coordinates, at half the loads and arithmetic.
template <uint32_t j>
inline void averaged_parallelogram(const uint64_t* c, const uint32_t* o, const uint32_t* more,
                                   uint64_t (&p)[3]) {
  const uint64_t *x = c + 3 * size_t(o[0]), *y = c + 3 * size_t(o[1]), *z = c + 3 * size_t(o[2]);
  if (!more) {
    for (int a = 0; a < 3; ++a) p[a] = damped_parallelogram(x[a], y[a], z[a], j);
    return;
  }
  const uint64_t *u = c + 3 * size_t(more[0]), *w = c + 3 * size_t(more[1]), *t = c + 3 * size_t(more[2]);
  for (int a = 0; a < 3; ++a)
    p[a] = uint64_t(int64_t((4 + j) * (x[a] + y[a] + u[a] + w[a]) - 2 * j * (z[a] + t[a]) + 8) >> 4);
}

// The plane prediction of predictive_node.hpp at the gate triangle x y z (coarse coordinates, wrapping):
// the dominant axis d of its normal n = (x - z) x (y - z) and, for the residuals ra, rb of axes d + 1, d + 2
// (mod 3), the offset floor(-(n[d+1] ra + n[d+2] rb) / n[d] + 1/2) of axis d's residual; d = 0 and offset 0
// when n = 0. In doubles, the same operations in the same order for the encoder and the decoder (no
// contraction: x86-64 has no FMA without -mfma), so both get the same bits. |n[d+1]|, |n[d+2]| <= |n[d]|, so
// |offset| <= |ra| + |rb| + 1 and the conversion back is in range for any residuals below 2^40 (hostile
// coordinates wrap in the cross product; any n is finite).
// With the multi-parallelogram prediction n is the sum of the normals of the two parallelograms' triangles
// (x, y, o), both in their mesh winding (traversal_connectivity.hpp, Parallelograms); without a second one
// (null), the gate's alone (the sum with itself would give the same plane and offsets for valid coordinates:
// doubling is exact in doubles).
inline void add_normal(const uint64_t* x, const uint64_t* y, const uint64_t* z, uint64_t (&n)[3]) {
  const uint64_t e[2][3] = {{x[0] - z[0], x[1] - z[1], x[2] - z[2]}, {y[0] - z[0], y[1] - z[1], y[2] - z[2]}};
  n[0] += e[0][1] * e[1][2] - e[0][2] * e[1][1];
  n[1] += e[0][2] * e[1][0] - e[0][0] * e[1][2];
  n[2] += e[0][0] * e[1][1] - e[0][1] * e[1][0];
}
struct PlaneGate {
  double along, first, second;  // n[d], n[d + 1], n[d + 2]
  uint32_t d;
  PlaneGate(const uint64_t* c, const uint32_t* o, const uint32_t* more) {
    uint64_t s[3] = {0, 0, 0};
    add_normal(c + 3 * size_t(o[0]), c + 3 * size_t(o[1]), c + 3 * size_t(o[2]), s);
    if (more) add_normal(c + 3 * size_t(more[0]), c + 3 * size_t(more[1]), c + 3 * size_t(more[2]), s);
    set(s);
  }
  // n's components in the order (d, d + 1, d + 2) taken by selects, not by an index into an array (which
  // put n on the stack: a store and reload on the decoder's chain from one vertex to the next).
  void set(const uint64_t (&s)[3]) {
    const double n0 = double(int64_t(s[0])), n1 = double(int64_t(s[1])), n2 = double(int64_t(s[2]));
    const double a0 = std::fabs(n0), a1 = std::fabs(n1), a2 = std::fabs(n2);
    d = a0 >= a1 ? (a0 >= a2 ? 0 : 2) : (a1 >= a2 ? 1 : 2);
    along = d == 0 ? n0 : d == 1 ? n1 : n2;
    first = d == 0 ? n1 : d == 1 ? n2 : n0;
    second = d == 0 ? n2 : d == 1 ? n0 : n1;
  }
  int64_t offset(int64_t ra, int64_t rb) const {
    if (along == 0.0) return 0;
    const double t = -(first * double(ra) + second * double(rb)) / along + 0.5;
    const int64_t i = int64_t(t);  // toward zero; floor below (no libm call)
    return i - (t < double(i));
  }
};

// c[v] = P + residual[v] per axis for v < V (predictive_node.hpp), wrapping, the residuals as read_planes
// leaves them (one array per component), with the plane prediction when `plane`. One pass, nothing but the
// prediction in it: the range check is a pass of its own (out_of_range), where OR-ing each result into an
// accumulator took 7 instructions a vertex and a register the loop spilled for, and the plane's lifted
// components return to their axes by selects, where an array indexed by d went through the stack, on the
// chain from one vertex to the next (refined_elephant's `bench decode`: decode_predicted_vertices 8.22 ->
// 7.85 M instructions under callgrind; rdtsc around the loop, each node's fastest of 15 runs summed: 0.88 ->
// 0.57 M ticks for the 47,649 vertices of nodes without the plane prediction, 1.39 -> 1.27 M for the 31,811
// with it, ~40 ticks a vertex there: the division's chain, predictive_node.hpp).
// With `extra` (multi), P is the multi-parallelogram (averaged_parallelogram) where a second one was found.
// Forced inline (and its dispatch below) into decode_predicted_vertices' builds, as read_planes.
template <uint32_t j, bool plane, bool multi>
[[gnu::always_inline]] inline void predict_positions(const int64_t* residual, uint32_t V, const uint32_t* o,
                                                     const Parallelograms* extra, uint64_t* c) {
  const uint64_t* r = reinterpret_cast<const uint64_t*>(residual);
  const uint8_t* const found = multi ? extra->found.data() : nullptr;
  const uint32_t* const corners = multi ? extra->corners.data() : nullptr;
  uint64_t* to = c;
  for (uint32_t v = 0; v < V; ++v, o += 3, to += 3, ++r) {
    const uint32_t* more = multi && found[v] ? corners + 3 * size_t(v) : nullptr;
    uint64_t p[3];
    averaged_parallelogram<j>(c, o, more, p);
    uint64_t q0 = r[0], q1 = r[V], q2 = r[2 * size_t(V)];
    if constexpr (plane) {
      // The lifted components (r[d] - offset, r[d + 1], r[d + 2]) back to axes: axis k takes component
      // (k - d) mod 3, by selects.
      const PlaneGate gate(c, o, more);
      const uint64_t lifted = q0 + uint64_t(gate.offset(int64_t(q1), int64_t(q2))), d = gate.d;
      const uint64_t x = d == 0 ? lifted : d == 1 ? q2 : q1, y = d == 0 ? q1 : d == 1 ? lifted : q2;
      q2 = d == 0 ? q2 : d == 1 ? q1 : lifted, q0 = x, q1 = y;
    }
    to[0] = p[0] + q0, to[1] = p[1] + q1, to[2] = p[2] + q2;
  }
}

template <uint32_t j>
[[gnu::always_inline]] inline void predict_positions(bool plane, const int64_t* residual, uint32_t V,
                                                     const uint32_t* o, const Parallelograms* extra,
                                                     uint64_t* c) {
  if (extra)
    plane ? predict_positions<j, true, true>(residual, V, o, extra, c)
          : predict_positions<j, false, true>(residual, V, o, extra, c);
  else
    plane ? predict_positions<j, true, false>(residual, V, o, extra, c)
          : predict_positions<j, false, false>(residual, V, o, extra, c);
}

// The plane kernels' lanes (below): 4 coordinates or components as GCC vectors, whose products each build
// compiles to its own instructions (x86-64-v4: VPMULLQ; AVX2: three VPMULUDQ, shifts and adds).
using Lanes = uint64_t __attribute__((vector_size(32)));
using SignedLanes = int64_t __attribute__((vector_size(32)));
using DoubleLanes = double __attribute__((vector_size(32)));

// A plane kernel's triangle: corners x, z and edges u = x - z, w = y - z of predictors t, one register each
// (lanes 0-2; lane 3 holds whatever follows a corner in c, which nothing reads: the kernels mask it out of
// every result). Plain 4-lane loads, where masked 3-lane ones took 12.4 TSC ticks a plane-predicted vertex
// rather than 11.6 (motorBike's AVX-512 build, measured as PlanesAvx512 says).
struct LaneTriangle {
  Lanes x, z, u, w;
};
__attribute__((target("avx2"))) [[gnu::always_inline]] inline LaneTriangle lane_triangle(const uint64_t* c,
                                                                                         const uint32_t* t) {
  Lanes x, y, z;
  __builtin_memcpy(&x, c + 3 * size_t(t[0]), sizeof x);
  __builtin_memcpy(&y, c + 3 * size_t(t[1]), sizeof y);
  __builtin_memcpy(&z, c + 3 * size_t(t[2]), sizeof z);
  return LaneTriangle{x, z, x - z, y - z};
}
// Its normal u x w (add_normal's), wrapping.
__attribute__((target("avx2"))) [[gnu::always_inline]] inline Lanes lane_normal(const LaneTriangle& t) {
  return __builtin_shufflevector(t.u, t.u, 1, 2, 0, 3) * __builtin_shufflevector(t.w, t.w, 2, 0, 1, 3) -
         __builtin_shufflevector(t.u, t.u, 2, 0, 1, 3) * __builtin_shufflevector(t.w, t.w, 1, 2, 0, 3);
}

// Vertex v's parallelogram P and the normal n of its plane (predictors o; with `multi` its second
// parallelogram where found[v], corners + 3v), wrapping (lanes 0-2): P is
// damped_parallelogram's, as x + w for j = 4 and from ((4 + j)(u + w) + 8z + 4) / 8 otherwise; with `multi`
// also averaged_parallelogram's P2 from ((4 + j)(u + w + u' + w') + 8(z + z') + 8) / 16 (equal modulo 2^64
// before the shift) and the normal n2 of v's second parallelogram, which the kernels take (P2, n + n2) where
// `more` (v has one) by their masks rather than a branch (elsewhere the second is the gate again, loaded but
// unused: corners holds stale entries there).
struct LanePrediction {
  Lanes p, n, p2, n2;
  bool more;
};
template <uint32_t j, bool multi>
__attribute__((target("avx2"))) [[gnu::always_inline]] inline LanePrediction lane_prediction(
    const uint64_t* c, const uint32_t* o, const uint8_t* found, const uint32_t* corners, uint32_t v) {
  const Lanes weight = Lanes{} + (4 + j);
  const LaneTriangle g = lane_triangle(c, o);
  const Lanes s = g.u + g.w;
  LanePrediction l{};
  l.p = j == 4 ? g.x + g.w : Lanes(SignedLanes(weight * s + (g.z << 3) + 4) >> 3);
  l.n = lane_normal(g);
  if constexpr (multi) {
    l.more = found[v];
    const LaneTriangle h = lane_triangle(c, l.more ? corners + 3 * size_t(v) : o);
    l.p2 = Lanes(SignedLanes(weight * (s + h.u + h.w) + ((g.z + h.z) << 3) + 8) >> 4);
    l.n2 = lane_normal(h);
  }
  return l;
}

// The plane kernels' tables, by the compare's bits k of dominant_axis: for each axis a, the component (a -
// d) mod 3 it takes (the lifted one, 0, at a = d) as the indices of its two 32-bit halves (VPERMD's), and
// lane d as a bit and as a lane mask.
alignas(32) constexpr int32_t kComponent[8][8] = {
    {2, 3, 4, 5, 0, 1, 6, 7}, {2, 3, 4, 5, 0, 1, 6, 7}, {4, 5, 0, 1, 2, 3, 6, 7}, {2, 3, 4, 5, 0, 1, 6, 7},
    {2, 3, 4, 5, 0, 1, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7}, {4, 5, 0, 1, 2, 3, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7}};
constexpr uint8_t kDominant[8] = {4, 4, 2, 4, 4, 1, 2, 1};
struct DominantLanes {
  alignas(32) int64_t mask[8][4];
};
constexpr DominantLanes kDominantLanes = [] {
  DominantLanes t{};
  for (int k = 0; k < 8; ++k)
    for (int a = 0; a < 4; ++a) t.mask[k][a] = kDominant[k] >> a & 1 ? -1 : 0;
  return t;
}();

// The compare's bits k (bit 0: |n0| >= |n1|, bit 1: |n1| >= |n2|, bit 2: |n0| >= |n2|) of n's lanes as
// doubles (`along`), whose dominant axis d is k & 1 ? (k & 4 ? 0 : 2) : (k & 2 ? 1 : 2) (PlaneGate::set's).
__attribute__((target("avx2"))) [[gnu::always_inline]] inline uint32_t dominant_axis(DoubleLanes along) {
  const __m256d size = _mm256_andnot_pd(_mm256_set1_pd(-0.0), __m256d(along));
  return _mm256_movemask_pd(_mm256_cmp_pd(_mm256_permute4x64_pd(size, _MM_SHUFFLE(3, 0, 1, 0)),
                                          _mm256_permute4x64_pd(size, _MM_SHUFFLE(3, 2, 2, 1)), _CMP_GE_OQ)) &
         7;
}

// The offsets of all three candidate axes before the rounding (lane a: axis a dominant, the same doubles
// and operations as PlaneGate::offset), from n's lanes as doubles and the residuals q: first (-ra) + second
// (-rb) is -(first ra + second rb) to the bit, the negation off the chain from one vertex to the next.
__attribute__((target("avx2"))) [[gnu::always_inline]] inline DoubleLanes candidate_offsets(DoubleLanes along,
                                                                                            SignedLanes q) {
  const DoubleLanes minus = -__builtin_convertvector(q, DoubleLanes);
  return (__builtin_shufflevector(along, along, 1, 2, 0, 3) *
              __builtin_shufflevector(minus, minus, 1, 1, 1, 1) +
          __builtin_shufflevector(along, along, 2, 0, 1, 3) *
              __builtin_shufflevector(minus, minus, 2, 2, 2, 2)) /
             along +
         0.5;
}

// The lifted residuals q (the plane's components) back to their axes by k's rotation.
__attribute__((target("avx2"))) [[gnu::always_inline]] inline Lanes components(SignedLanes q, uint32_t k) {
  return Lanes(_mm256_permutevar8x32_epi32(
      __m256i(q), _mm256_load_si256(reinterpret_cast<const __m256i*>(kComponent[k]))));
}

// predict_positions<j, true, multi> (the plane prediction) in 4 lanes, to the bit, as PlanesAvx512 and
// PlanesAvx2 build it: a vertex's coordinates, edges, parallelogram and normal in the lanes of one register
// each (lane_prediction), the offsets of all three candidate axes at once (candidate_offsets) and the
// dominant axis as an index into tables (which rotation of the components, which lane's offset) from one
// compare of |n|'s lanes (dominant_axis), where the scalar kernel branched on it (the axis changes at 19 %
// of motorBike's plane-predicted vertices). The two differ where AVX2 lacks AVX-512's instructions (the
// conversions between int64 and double lanes, mask registers): one kernel with AVX2's forms for both took
// motorBike's AVX-512 build from 12.1 to 14.7 TSC ticks a plane-predicted vertex.
// Measured (rdtsc around the prediction, each node's fastest of 15 runs summed, interleaved runs):
// motorBike's 301,608 vertices of plane-predicted nodes 22.2 -> 13.2 TSC ticks a vertex, 12.4 with the
// negation and the rounding below (9.4 -> 8.8 where nothing depends on the vertices just written: the rest is
// the chain from one vertex to the next); with the multi-parallelogram prediction, refined_elephant's 16,274
// vertices 33.8 -> 18.9, motorBike's 6,687 32.5 -> 21.6. Coordinates are read 4 lanes at a time (c holds one
// entry past cmin's coordinates for the last read) and written 3 (masked: cmin's stay).
struct PlanesAvx512 {
  template <uint32_t j, bool multi>
  __attribute__((target("arch=x86-64-v4"))) static void predict(const int64_t* residual, uint32_t V,
                                                                const uint32_t* o,
                                                                const Parallelograms* extra, uint64_t* c) {
    const uint8_t* const found = multi ? extra->found.data() : nullptr;
    const uint32_t* const corners = multi ? extra->corners.data() : nullptr;
    for (uint32_t v = 0; v < V; ++v, o += 3) {
      const LanePrediction l = lane_prediction<j, multi>(c, o, found, corners, v);
      __m256i p = __m256i(l.p), n = __m256i(l.n);
      if constexpr (multi) {
        const __mmask8 more = l.more ? 7 : 0;
        p = _mm256_mask_mov_epi64(p, more, __m256i(l.p2));
        n = _mm256_mask_add_epi64(n, more, n, __m256i(l.n2));
      }
      const DoubleLanes along = __builtin_convertvector(SignedLanes(n), DoubleLanes);
      const uint32_t k = dominant_axis(along);
      const SignedLanes q = {residual[v], residual[V + v], residual[2 * size_t(V) + v], 0};
      // floor(t) in lane d alone, 0 where n = 0 (then every lane of `along` is), converted rounding down in
      // one instruction (embedded rounding takes 512-bit registers; the low half taken by a shuffle, where
      // GCC 12's _mm512_castsi512_si256 warns of its undefined upper lanes).
      const __mmask8 lane =
          _mm256_cmp_pd_mask(__m256d(along), _mm256_setzero_pd(), _CMP_NEQ_UQ) & kDominant[k];
      using Int64x8 = long long __attribute__((vector_size(64)));
      const Int64x8 all = Int64x8(
          _mm512_maskz_cvt_roundpd_epi64(lane, _mm512_castpd256_pd512(__m256d(candidate_offsets(along, q))),
                                         _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC));
      const Lanes offset = Lanes(__builtin_shufflevector(all, all, 0, 1, 2, 3));
      _mm256_mask_storeu_epi64(c + 3 * size_t(v), 7, __m256i(Lanes(p) + components(q, k) + offset));
    }
  }
};

// The AVX2 build of the plane kernel (PlanesAvx512's steps), n's lanes converted to doubles by their bits
// (to_double: VCVTQQ2PD is AVX-512's; GCC's conversion of the lanes one at a time took 23.1 TSC ticks a
// vertex, this 19.3), the offset's floor by adding 1.5 * 2^52 to it (exact below 2^51: |offset| <= 2^41,
// PlaneGate) and all 4 lanes written but at the last vertex (lane 3 into v + 1's x, which nothing reads
// before v + 1 writes it: predictors lie below it). Measured (rdtsc around the prediction of all
// plane-predicted nodes, `bench decode --runs 5`, fastest of 8 interleaved runs), against the scalar
// kernel: motorBike 22.1 -> 19.2 ticks a vertex, refined_elephant (multi-parallelogram nodes) 29.7 -> 21.6.
struct PlanesAvx2 {
  // The lanes of n as doubles, rounded as a conversion: (n >> 48) 2^48 - 2^52 exactly, from its bits added
  // to 3 * 2^67's, then 2^52 + (n mod 2^48), from its bits in 2^52's mantissa, added (one rounding).
  __attribute__((target("avx2"))) [[gnu::always_inline]] static DoubleLanes to_double(Lanes n) {
    const __m256i high = _mm256_blend_epi16(_mm256_srai_epi32(__m256i(n), 16), _mm256_setzero_si256(), 0x33);
    const __m256i low = _mm256_blend_epi16(__m256i(n), _mm256_castpd_si256(_mm256_set1_pd(0x1p52)), 0x88);
    const DoubleLanes h = DoubleLanes(Lanes(high) + Lanes(DoubleLanes{} + 0x3p67)) - (0x3p67 + 0x1p52);
    return h + DoubleLanes(low);
  }
  template <uint32_t j, bool multi>
  __attribute__((target("avx2"))) static void predict(const int64_t* residual, uint32_t V, const uint32_t* o,
                                                      const Parallelograms* extra, uint64_t* c) {
    const DoubleLanes magic = DoubleLanes{} + 0x1.8p52;
    const uint8_t* const found = multi ? extra->found.data() : nullptr;
    const uint32_t* const corners = multi ? extra->corners.data() : nullptr;
    for (uint32_t v = 0; v < V; ++v, o += 3) {
      LanePrediction l = lane_prediction<j, multi>(c, o, found, corners, v);
      if constexpr (multi) {
        const Lanes more = Lanes{} - uint64_t(l.more);
        l.p = (l.p & ~more) | (l.p2 & more), l.n += l.n2 & more;
      }
      const DoubleLanes along = to_double(l.n);
      const uint32_t k = dominant_axis(along);
      const SignedLanes q = {residual[v], residual[V + v], residual[2 * size_t(V) + v], 0};
      // floor(t) in lane d alone, 0 where n = 0 (then every lane of `along` is).
      const SignedLanes lane =
          SignedLanes(_mm256_load_si256(reinterpret_cast<const __m256i*>(kDominantLanes.mask[k]))) &
          (along != 0.0);
      const DoubleLanes floor =
          DoubleLanes(SignedLanes(_mm256_floor_pd(__m256d(candidate_offsets(along, q)))) & lane);
      const Lanes result = l.p + components(q, k) + (Lanes(floor + magic) - Lanes(magic));
      if (v + 1 < V)
        __builtin_memcpy(c + 3 * size_t(v), &result, sizeof result);
      else
        _mm256_maskstore_epi64(reinterpret_cast<long long*>(c + 3 * size_t(v)),
                               _mm256_set_epi64x(0, -1, -1, -1), __m256i(result));
    }
  }
};

// Kernel's plane kernel (PlanesAvx512 or PlanesAvx2) with the damping j = 4, 3 or 2, and the
// multi-parallelogram prediction where `extra` is not null: a call per node.
template <typename Kernel>
void predict_plane_positions(uint32_t j, const int64_t* residual, uint32_t V, const uint32_t* o,
                             const Parallelograms* extra, uint64_t* c) {
  if (j == 4)
    extra ? Kernel::template predict<4, true>(residual, V, o, extra, c)
          : Kernel::template predict<4, false>(residual, V, o, extra, c);
  else if (j == 3)
    extra ? Kernel::template predict<3, true>(residual, V, o, extra, c)
          : Kernel::template predict<3, false>(residual, V, o, extra, c);
  else
    extra ? Kernel::template predict<2, true>(residual, V, o, extra, c)
          : Kernel::template predict<2, false>(residual, V, o, extra, c);
}

// Whether any of c[0 .. n) lies outside [-kMaxCoarse, kMaxCoarse): their shifted values OR-ed, one pass that
// vectorizes (4 values an instruction in the AVX2 build). Cost: O(n).
[[gnu::always_inline]] inline bool out_of_range(const uint64_t* c, size_t n) {
  uint64_t shifted = 0;  // in range while below 2 kMaxCoarse
  for (size_t i = 0; i < n; ++i) shifted |= c[i] + uint64_t(kMaxCoarse);
  return shifted >= 2 * uint64_t(kMaxCoarse);
}

// Bits of a zigzagged residual (0 for 0): the encoder's estimate of what a damping costs.
inline uint32_t residual_bits(uint64_t z) {
  return z ? 64 - uint32_t(__builtin_clzll(z)) : 0;
}

}  // namespace

namespace {

// What parse and layout share: the header, widths and stream sizes of a node of node_size bytes, read from
// r, checked to fit; `sizes` gets the attribute, locked and connectivity streams' sizes.
PredictiveNode read_layout(ByteReader& r, size_t node_size, uint8_t format, uint32_t known_flags,
                           uint64_t (&sizes)[3]) {
  PredictiveNode p;
  static_cast<NodeHeader&>(p) = NodeHeader::read(r, format, known_flags, node_size);
  const uint8_t widths = r.u8();
  p.position_bytes = widths & 7, p.smooth_normals = (widths >> 3) & 1;
  p.normal_bytes = (widths >> 4) & 3, p.damping = 4 - (widths >> 6);
  if (p.position_bytes < 1 || p.position_bytes > kMaxPositionBytes || p.damping < 2 ||
      (p.normal_bytes == 0) != !(p.flags & kHasNormals) || (p.smooth_normals && p.normal_bytes == 0))
    r.fail("invalid residual widths");
  const uint64_t attribute_size = r.varint(), locked_size = r.varint(), connectivity_size = r.varint();
  p.header_size = r.position();
  const uint64_t planes = uint64_t(p.vertices) * (3 * p.position_bytes + 2 * p.normal_bytes);  // V ≤ 65536
  const uint64_t remaining = node_size - std::min<uint64_t>(node_size, p.header_size);
  if (p.header_size > node_size || planes > remaining || attribute_size > remaining - planes ||
      locked_size > remaining - planes - attribute_size ||
      connectivity_size > remaining - planes - attribute_size - locked_size)
    r.fail("stream sizes do not add up to the node size");
  sizes[0] = attribute_size, sizes[1] = locked_size, sizes[2] = connectivity_size;
  return p;
}

}  // namespace

PredictiveNode PredictiveNode::parse(std::span<const uint8_t> bytes, uint8_t format, uint32_t known_flags,
                                     const std::string& where) {
  ByteReader r(bytes, where);
  uint64_t sizes[3];
  PredictiveNode p = read_layout(r, bytes.size(), format, known_flags, sizes);
  p.position_planes = r.bytes(size_t(3) * p.position_bytes * p.vertices, "position residuals");
  p.normal_planes = r.bytes(size_t(2) * p.normal_bytes * p.vertices, "normal residuals");
  p.attribute_stream = r.bytes(sizes[0], "attribute stream");
  p.locked_stream = r.bytes(sizes[1], "locked stream");
  p.connectivity = r.bytes(sizes[2], "connectivity");
  p.tail = r.bytes(r.remaining(), "tail");
  return p;
}

NodeSizeBreakdown PredictiveNode::layout(std::span<const uint8_t> bytes, size_t node_size, uint8_t format,
                                         uint32_t known_flags, const std::string& where, uint64_t* tail) {
  ByteReader r(bytes, where);
  uint64_t sizes[3];
  const PredictiveNode p = read_layout(r, node_size, format, known_flags, sizes);
  NodeSizeBreakdown b;
  b.header = p.header_size;
  b.normals = size_t(2) * p.normal_bytes * p.vertices, b.attributes = sizes[0];
  b.vertices = size_t(3) * p.position_bytes * p.vertices + b.normals + b.attributes;
  b.position_low = size_t(3) * p.vertices, b.normal_low = p.normal_bytes ? size_t(2) * p.vertices : 0;
  b.locked = sizes[1];
  b.indices = node_size - b.header - b.vertices - b.locked;  // connectivity and tail
  if (tail) *tail = b.indices - sizes[2];
  b.stored_vertices = p.vertices;
  return b;
}

PredictiveResiduals predictive_residuals(const NodeGeometry& g, const QuantizedNode& n,
                                         std::span<const uint32_t> predictors,
                                         std::span<const uint32_t> multi_predictors,
                                         const Parallelograms* extra, std::span<const uint32_t> indices,
                                         std::span<const uint8_t> locked_stream, const PositionGrid& grid) {
  const size_t V = n.order.size();
  PredictiveResiduals r;
  // The coordinates with entry V holding cmin (what a predictor V stands for), in a buffer kept across nodes.
  thread_local std::vector<int64_t> c;
  c.assign(n.c.begin(), n.c.end());
  c.insert(c.end(), std::begin(n.cmin), std::end(n.cmin));
  // The damping j, plane and multi-parallelogram prediction whose residuals take the fewest bits (ties:
  // the larger j, no plane, no multi): one pass counts all twelve (the gate's plane does not depend on j),
  // then the choice's residuals.
  const uint64_t* cu = reinterpret_cast<const uint64_t*>(c.data());
  // Vertex v's predictors and second parallelogram (null without the multi prediction or where none was
  // found: averaged_parallelogram is then the gate's).
  auto corners = [&](size_t v, bool multi, const uint32_t*& o, const uint32_t*& more) {
    o = &(multi ? multi_predictors : predictors)[3 * v];
    more = multi && extra->found[v] ? extra->corners.data() + 3 * v : nullptr;
  };
  // Vertex v's residuals at damping j, plain (d), and lifted onto the plane of `gate` (e: components (d -
  // offset, d + 1, d + 2) of its dominant axis d).
  auto plain_at = [&](size_t v, uint32_t j, const uint32_t* o, const uint32_t* more, int64_t(&d)[3]) {
    uint64_t p[3];
    j == 4   ? averaged_parallelogram<4>(cu, o, more, p)
    : j == 3 ? averaged_parallelogram<3>(cu, o, more, p)
             : averaged_parallelogram<2>(cu, o, more, p);
    for (int a = 0; a < 3; ++a) d[a] = c[3 * v + a] - int64_t(p[a]);
  };
  auto lifted = [](const PlaneGate& gate, const int64_t(&d)[3], int64_t(&e)[3]) {
    const uint32_t k = gate.d, a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
    e[0] = d[k] - gate.offset(d[a], d[b]), e[1] = d[a], e[2] = d[b];
  };
  // [multi][plane][j]: the residuals' bit lengths summed, and OR-ed (bytes_for needs only the highest bit).
  uint64_t bits[2][2][5] = {}, high[2][2][5] = {};
  const int multis = extra ? 2 : 1;
  for (size_t v = 0; v < V; ++v)
    for (int multi = 0; multi < multis; ++multi) {
      const uint32_t *o, *more;
      corners(v, multi, o, more);
      const PlaneGate gate(cu, o, more);  // the same for every j
      for (uint32_t j = 2; j <= 4; ++j) {
        int64_t d[2][3];
        plain_at(v, j, o, more, d[0]);
        lifted(gate, d[0], d[1]);
        for (int plane = 0; plane < 2; ++plane)
          for (int i = 0; i < 3; ++i) {
            const uint64_t z = zigzag(d[plane][i]);
            bits[multi][plane][j] += residual_bits(z), high[multi][plane][j] |= z;
          }
      }
    }
  // The multi-parallelogram prediction must save kMultiMinSavedBits quarter bits a vertex (its decode cost).
  uint64_t fewest = UINT64_MAX;
  for (int multi = 0; multi < multis; ++multi)
    for (int plane = 0; plane < 2; ++plane)
      for (uint32_t j = 4; j >= 2; --j)
        if (bits[multi][plane][j] + (multi ? kMultiMinSavedBits * V / 4 : 0) < fewest)
          fewest = bits[multi][plane][j], r.damping = j, r.plane = plane, r.multi = multi,
          r.position_bytes = bytes_for(high[multi][plane][j]);
  r.positions.resize(3 * V);
  for (size_t v = 0; v < V; ++v) {
    const uint32_t *o, *more;
    corners(v, r.multi, o, more);
    int64_t d[2][3];
    plain_at(v, r.damping, o, more, d[0]);
    if (r.plane) lifted(PlaneGate(cu, o, more), d[0], d[1]);
    for (int i = 0; i < 3; ++i) r.positions[3 * v + i] = zigzag(d[r.plane][i]);
  }
  if (g.mesh->has_normals()) {
    // Kept across nodes: decode_positions overwrites the first V; predicted_normals reads one past them
    // (lanes it never uses).
    thread_local std::vector<glm::vec3> decoded;
    decoded.resize(V + 1);
    decode_positions(n.c, LockedStream::parse(locked_stream, V, g.position_shift, "node codec"), grid,
                     decoded.data());
    NormalCodes codes = code_normals(g.mesh->normals, n.order, indices, g.first_vertex, n.index_end,
                                     decoded.data(), g.normal_bits);
    r.normals = std::move(codes.codes), r.normal_bytes = codes.width, r.smooth_normals = codes.smooth;
    if (g.normal_bits <= kDerivedNormalBits) {
      std::vector<uint8_t> open;
      open_vertices(indices, g.first_vertex, uint32_t(V), open);
      derive_closed_normals(r.normals, open);
    }
  }
  return r;
}

std::vector<uint8_t> write_predictive_node(const NodeHeader& header, const PredictiveResiduals& r,
                                           std::span<const uint8_t> attribute_stream,
                                           std::span<const uint8_t> locked_stream,
                                           std::span<const uint8_t> connectivity,
                                           std::span<const uint8_t> tail) {
  ByteWriter w;
  NodeHeader h = header;
  if (r.plane) h.flags |= kPlanePrediction;
  if (r.multi) h.flags |= kMultiParallelogram;
  h.write(w);
  w.u8(static_cast<uint8_t>(r.position_bytes | r.smooth_normals << 3 | r.normal_bytes << 4 |
                            (4 - r.damping) << 6));
  w.varint(attribute_stream.size());
  w.varint(locked_stream.size());
  w.varint(connectivity.size());
  put_planes(w.bytes, r.positions, 3, r.position_bytes);
  if (r.normal_bytes) put_planes(w.bytes, r.normals, 2, r.normal_bytes);
  w.raw(attribute_stream);
  w.raw(locked_stream);
  w.raw(connectivity);
  w.raw(tail);
  return std::move(w.bytes);
}

namespace {

// decode_predicted_vertices' body, forced inline into each of its builds below; `Planes` (PlanesAvx512 or
// PlanesAvx2) for plane-predicted nodes where not void.
template <typename Planes = void>
[[gnu::always_inline]] inline void decode_vertices(const PredictiveNode& p,
                                                   std::span<const uint32_t> predictors,
                                                   const Parallelograms* extra, const PositionGrid& grid,
                                                   DecodedNode& out, const std::string& where) {
  const uint32_t V = p.vertices;
  Mesh& m = out.mesh;
  const LockedStream locked = LockedStream::parse(p.locked_stream, V, p.shift, where);
  // c[v] = P + residual (the damped parallelogram), with entry V holding cmin, the residuals read from their
  // planes first (one vectorized pass). The arithmetic wraps (unsigned), so hostile residuals cannot
  // overflow; the results are range-checked after it (out_of_range). One entry more, which the AVX-512
  // build's 4-lane reads of cmin's 3 coordinates take (lane_triangle).
  thread_local std::vector<int64_t> c;
  grow_scratch(c, 3 * (size_t(V) + 1) + 1);
  uint64_t* cu = reinterpret_cast<uint64_t*>(c.data());
  for (int a = 0; a < 3; ++a) cu[3 * size_t(V) + a] = uint64_t(p.cmin[a]);
  thread_local std::vector<int64_t> residual;
  grow_scratch(residual, 3 * size_t(V));
  read_planes(p.position_planes.data(), V, 3, p.position_bytes, residual.data());
  const bool plane = p.flags & kPlanePrediction;
  if (!std::is_void_v<Planes> && plane) {
    if constexpr (!std::is_void_v<Planes>)
      predict_plane_positions<Planes>(p.damping, residual.data(), V, predictors.data(), extra, cu);
  } else if (p.damping == 4)
    predict_positions<4>(plane, residual.data(), V, predictors.data(), extra, cu);
  else if (p.damping == 3)
    predict_positions<3>(plane, residual.data(), V, predictors.data(), extra, cu);
  else
    predict_positions<2>(plane, residual.data(), V, predictors.data(), extra, cu);
  if (out_of_range(cu, 3 * size_t(V))) throw Error(where + ": predicted position out of the grid's range");
  // Decoded straight into m.positions with one spare entry for predicted_normals, dropped after it: a
  // record's mesh is reused (PackageReader's last record), so the resize zero-fills only what it grows by,
  // where decoding into scratch copied every position (refined_elephant's bench decode: 0.9 M of memcpy).
  m.positions.resize(size_t(V) + 1);
  decode_positions(std::span(c).first(3 * size_t(V)), locked, grid, m.positions.data());
  if (p.flags & kHasNormals) {
    thread_local std::vector<NormalSum> sum;
    predicted_normals(m.indices, p.first_vertex, p.index_end, m.positions.data(), V, p.smooth_normals, sum);
    decode_predicted_normals(sum, V, p.normal_planes.data(), p.normal_bytes, p.normal_bits, m.normals);
  } else {
    m.normals.clear();
  }
  m.positions.resize(V);
  decode_attribute_stream(p.attribute_stream, p.flags, V, p.uv_min, p.uv_extent, out, where);
}

// The AVX-512 (x86-64-v4) build: 10.8 TSC ticks a vertex from the residual planes to the range-checked coarse
// coordinates, where the AVX2 build takes 11.6 (rdtsc around them, each node's fastest of 15 runs summed over
// elephant_1m's 1.31 M vertices, median of 10 interleaved pairs: 15.2 -> 14.1 M ticks, 0.925x); read_planes
// and out_of_range take 16 lanes a step. With PlanesAvx512 (5 interleaved runs each, the
// same harness): elephant_1m 10.5 -> 6.7 ticks a vertex, motorBike 22.0 -> 12.3, refined_elephant 18.3 ->
// 11.3. Without contraction (CMakeLists.txt's -ffp-contract=off: x86-64-v4
// includes FMA), so the plane prediction's doubles give the same bits as the other builds.
__attribute__((target("arch=x86-64-v4"))) void decode_vertices_avx512(
    const PredictiveNode& p, std::span<const uint32_t> predictors, const Parallelograms* extra,
    const PositionGrid& grid, DecodedNode& out, const std::string& where) {
  decode_vertices<PlanesAvx512>(p, predictors, extra, grid, out, where);
}

}  // namespace

void decode_predicted_vertices_baseline(const PredictiveNode& p, std::span<const uint32_t> predictors,
                                        const Parallelograms* extra, const PositionGrid& grid,
                                        DecodedNode& out, const std::string& where) {
  decode_vertices(p, predictors, extra, grid, out, where);
}

// An AVX2 build, as predicted_normals (no FMA: the same bits): VEX's 3-operand forms and wider byte-plane
// reads (`bench decode --runs 1` under callgrind, decode_node: refined_elephant 45.88 -> 45.80 M
// instructions, elephant_1m 689.6 -> 687.9 M). With PlanesAvx2 (the same, valgrind runs this build; this
// function with what it calls): refined_elephant 17.01 -> 15.86 M, motorBike 74.61 -> 68.82 M.
__attribute__((target("avx2"))) void decode_predicted_vertices_avx2(
    const PredictiveNode& p, std::span<const uint32_t> predictors, const Parallelograms* extra,
    const PositionGrid& grid, DecodedNode& out, const std::string& where) {
  decode_vertices<PlanesAvx2>(p, predictors, extra, grid, out, where);
}

void decode_predicted_vertices(const PredictiveNode& p, std::span<const uint32_t> predictors,
                               const Parallelograms* extra, const PositionGrid& grid, DecodedNode& out,
                               const std::string& where) {
  call_widest_build(decode_vertices_avx512, decode_predicted_vertices_avx2,
                    decode_predicted_vertices_baseline, p, predictors, extra, grid, out, where);
}

}  // namespace lodstream::package
