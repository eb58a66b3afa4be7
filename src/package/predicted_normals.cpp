// Float8 values (decode_predicted_normals) pass only between inline functions of this file and
// octahedral.hpp: GCC's note that their ABI differs without AVX (-Wpsabi) does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

#include "package/predicted_normals.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>

#include "package/byte_planes.hpp"
#include "package/octahedral.hpp"
#include "package/scratch.hpp"
#include "package/widest_build.hpp"

namespace lodstream::package {

namespace {

// (v.y, v.z, v.x, v.w): the rotation of a cross product's operands.
NormalSum rotate(NormalSum v) {
  return shuffle<1, 2, 0, 3>(v, v);
}

// The orthonormal frame (t, b, p) of 4 (Float4) or 8 (Float8) predictions, lane i from (x[i], y[i], z[i]):
// p the unit prediction (+z for a zero or non-finite sum), t and b from Duff et al. 2017, "Building an
// Orthonormal Basis, Revisited" (JCGT 6(1), listing 3): with s = sign(p.z), a = -1 / (s + p.z), c = p.x p.y
// a, t = (1 + s p.x^2 a, s c, -s p.x), b = (c, s + p.y^2 a, -p.y). The encoder and the decoder both call it,
// so that they work in the same frame to the bit (the frame jumps where p.z changes sign; the same
// operations in every lane, however many lanes). Forced inline (as transpose): out of line, the decoder's
// AVX2 build called it and spilled the frame per 4 vertices (1.8 % more decode instructions on
// refined_elephant).
template <class V>
struct Frame {
  V t[3], b[3], p[3];
};
template <class V>
[[gnu::always_inline]] inline Frame<V> prediction_frame(V x, V y, V z) {
  const V zero = splat_as<V>(0.0f), one = splat_as<V>(1.0f);
  const V length2 = x * x + y * y + z * z;
  // Usable: 0 < length2 <= FLT_MAX (not zero, NaN or infinite), as one unsigned comparison of its bits
  // minus 1 (bits 1 .. 0x7f7fffff, the positive finite floats): GCC 12 scalarizes the AND of two 16-lane
  // float comparisons in the AVX-512 build.
  typedef uint32_t U __attribute__((vector_size(sizeof(V))));
  const decltype(x < x) usable = U(length2) - 1 <= 0x7f7ffffe;
  const V inv_length = one / sqrt(select(usable, length2, one));
  Frame<V> f;
  f.p[0] = select(usable, x * inv_length, zero), f.p[1] = select(usable, y * inv_length, zero);
  f.p[2] = select(usable, z * inv_length, one);
  const V s = select(f.p[2] >= zero, one, -one);
  const V a = -one / (s + f.p[2]), c = f.p[0] * f.p[1] * a;
  f.t[0] = one + s * f.p[0] * f.p[0] * a, f.t[1] = s * c, f.t[2] = -s * f.p[0];
  f.b[0] = c, f.b[1] = s + f.p[1] * f.p[1] * a, f.b[2] = -f.p[1];
  return f;
}

// The scale of the codes in a prediction's frame (oct_encode's, of the normal as the frame sees it): a
// fraction of the b-bit global code's 2^(b-1) - 1 that gives the global code's RMS angular error. 0.52
// measured over the normals of elephant_1m, refined_elephant and motorBike: 0.37 against 0.37 degrees at 8
// bits, but 0.18 against 0.19 at 9 (level 0's normals, where predictions are closest), so 9 bits take
// 0.52 * 0.18 / 0.19 = 0.49 (helper coarsepos2: elephant_1m -0.4 %, refined_elephant -0.3 %, motorBike
// -0.1 %; renders at 1 px from six views the same triangles, PSNR within 0.001 dB). Near the prediction
// the frame's codes are finer than the global ones (the octahedral map stretches least around its poles),
// far from it coarser.
float frame_scale(uint32_t bits) {
  return (bits == 9 ? 0.49f : 0.52f) * static_cast<float>((1 << (bits - 1)) - 1);
}

// The encoder's rounding offset of the codes in a prediction's frame (oct_encode): below 0.5 it rounds toward
// the prediction, a dead-zone quantizer (the residuals are peaked at 0, so a code nearer zero saves more bits
// than its larger error costs). 9 bits (level 0 and progressive meshes by default) take 0.2, fewer bits
// (coarser clusters) 0.4; more than 9 bits, a precision asked for explicitly, rounds to the nearest code.
// Measured (bake, render at 1 px, measure --images against the full model; elephant_1m near / mid / far,
// refined_elephant the same, motorBike front / side / above): offsets 0.5 / 0.4 / 0.35 / 0.25 everywhere gave
// elephant_1m 3,929,606 / 3,874,189 / 3,846,263 / 3,791,792 B, refined_elephant 333,606 / 330,060 / 328,499
// / 325,248 B, motorBike 1,647,075 / 1,636,864 / 1,632,486 / 1,624,476 B; below 0.4 coarse clusters cost
// refined_elephant's far view 0.086 dB (0.35) and 0.11 dB (0.25). With 0.4 below 9 bits, 0.3 / 0.2 / 0.1 at
// 9 bits: 3,843,361 / 3,813,972 / 3,786,481 B, 328,149 / 326,598 / 325,330 B, 1,633,844 / 1,631,598 /
// 1,630,137 B; PSNR at 0.2 48.594 / 61.088 / 61.429, 46.586 / 53.576 / 59.952, 47.791 / 45.998 / 48.044
// dB against 48.599 / 61.097 / 61.434, 46.594 / 53.559 / 59.937, 47.786 / 46.000 / 48.067 with nearest
// rounding at 8 bits everywhere above level 0 (at most -0.023 dB; 0.1: motorBike above -0.031 dB, left for
// the margin that 9 bits keep for close-up and specular views), the same triangles. Decoders are unchanged:
// any code decodes as before.
float rounding_offset(uint32_t bits) {
  return bits > 9 ? 0.5f : bits == 9 ? 0.2f : 0.4f;
}

// in_lanes<I0, I1, I2, I3>(a, b): shuffle<I...> of Float4s, and of Float8s and Float16s the same in each
// 4-lane (128-bit) lane (lanes 4j .. 4j+3 from the lanes 4j .. 4j+3 of a and b: AVX's and AVX-512's in-lane
// unpacks and shuffles).
template <int... I>
[[gnu::always_inline]] inline Float4 in_lanes(Float4 a, Float4 b) {
  return shuffle<I...>(a, b);
}
template <int... I>
[[gnu::always_inline]] inline Float8 in_lanes(Float8 a, Float8 b) {
#if defined(__clang__)
  return __builtin_shufflevector(a, b, (I < 4 ? I : I + 4)..., (I < 4 ? I + 4 : I + 8)...);
#else
  return __builtin_shuffle(a, b, Int8{(I < 4 ? I : I + 4)..., (I < 4 ? I + 4 : I + 8)...});
#endif
}
template <int... I>
[[gnu::always_inline]] inline Float16 in_lanes(Float16 a, Float16 b) {
#if defined(__clang__)
  return __builtin_shufflevector(a, b, (I < 4 ? I : I + 12)..., (I < 4 ? I + 4 : I + 16)...,
                                 (I < 4 ? I + 8 : I + 20)..., (I < 4 ? I + 12 : I + 24)...);
#else
  return __builtin_shuffle(a, b,
                           Int16{(I < 4 ? I : I + 12)..., (I < 4 ? I + 4 : I + 16)...,
                                 (I < 4 ? I + 8 : I + 20)..., (I < 4 ? I + 12 : I + 24)...});
#endif
}

// Lanes 0-2 of sum[i .. i+3] (Float4), sum[i .. i+7] (Float8) or sum[i .. i+15] (Float16) transposed into
// x, y, z, lane k from vertex i + k: a 4 x 4 transpose in each 128-bit lane, a Float8's registers loaded as
// (sum[i+k] | sum[i+4+k]), a Float16's as (sum[i+k] | sum[i+4+k] | sum[i+8+k] | sum[i+12+k]). In 8 lanes
// ~13 instructions, where two 4-lane transposes joined took ~30 (GCC gathered the joined lanes one float at a
// time; `bench decode --runs 1` under callgrind, decode_predicted_normals with store_normals' 8 lanes below:
// refined_elephant 2.11 -> 1.87 M, elephant_1m 33.6 -> 29.7 M).
template <class V>
[[gnu::always_inline]] inline void transpose(const NormalSum* s, V& x, V& y, V& z) {
  V r[4];
  for (size_t k = 0; k < 4; ++k)
    for (size_t h = 0; h < sizeof(V) / sizeof(NormalSum); ++h)
      std::memcpy(reinterpret_cast<char*>(&r[k]) + h * sizeof(NormalSum), &s[4 * h + k], sizeof(NormalSum));
  const V xy01 = in_lanes<0, 4, 1, 5>(r[0], r[1]), xy23 = in_lanes<0, 4, 1, 5>(r[2], r[3]);
  const V z01 = in_lanes<2, 6, 3, 7>(r[0], r[1]), z23 = in_lanes<2, 6, 3, 7>(r[2], r[3]);
  x = in_lanes<0, 1, 4, 5>(xy01, xy23), y = in_lanes<2, 3, 6, 7>(xy01, xy23);
  z = in_lanes<0, 1, 4, 5>(z01, z23);
}

}  // namespace

// target_clones: an AVX2 build of the function besides the baseline one, chosen once at load time (ifunc);
// VEX's 3-operand forms save the register copies that 2-operand SSE needs. Neither build contracts a multiply
// and an add (AVX2 does not include FMA), so both compute the same bits.
__attribute__((target_clones("avx2", "default"))) void predicted_normals(
    std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t index_end, const glm::vec3* positions,
    uint32_t V, bool smooth, std::vector<NormalSum>& sum) {
  // Lanes 0-2 of a 16-byte load at positions[v] are its x y z; lane 3 (the next vertex's x) is never read.
  auto p = [positions](uint32_t v) {
    NormalSum r;
    std::memcpy(&r, &positions[v], sizeof r);
    return r;
  };
  // Zeros: the entries sum held before cleared, the rest value-initialised by the resize, not both
  // (motorBike's `bench decode --runs 1` under callgrind: memset here 5.37 -> 4.16 M instructions).
  const size_t held = std::min(sum.size(), (size_t(V) + 3) & ~size_t(3));
  sum.resize((size_t(V) + 3) & ~size_t(3));
  std::memset(sum.data(), 0, held * sizeof(NormalSum));
  // With all_inside, first_vertex is 0 (the caller's condition below): a constant, so no subtraction.
  auto accumulate = [&](auto all_inside) {
    const uint32_t base = all_inside ? 0 : first_vertex;
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
      const uint32_t a = indices[i] - base, b = indices[i + 1] - base, c = indices[i + 2] - base;
      if (!all_inside && (a >= V || b >= V || c >= V)) continue;
      // cross(e, f) = e.yzx * f.zxy - e.zxy * f.yzx, as glm::cross computes each component, here as the
      // rotation of e * f.yzx - e.yzx * f (lane i: e[i] f[i + 1] - e[i + 1] f[i], the same products and
      // difference): three shuffles a triangle instead of four (refined_elephant's `bench decode --runs 1`
      // under callgrind: predicted_normals 6.22 -> 6.07 M instructions).
      const NormalSum pa = p(a), e = p(b) - pa, f = p(c) - pa;
      const NormalSum n = rotate(e * rotate(f) - rotate(e) * f);
      sum[a] += n, sum[b] += n, sum[c] += n;
    }
  };
  // s'[v] = 2 s[v] + sum over v's triangles of the other two corners' s: with t = s[a] + s[b] + s[c], corner
  // a gains t - s[a]. The plain sums move to `plain` (a swap of buffers, no copy) and sum is written 2 s
  // from them.
  thread_local std::vector<NormalSum> plain;
  auto smoothen = [&](auto all_inside) {
    const uint32_t base = all_inside ? 0 : first_vertex;
    std::swap(plain, sum);
    sum.resize(plain.size());
    // Two sums a step (a count that is a multiple of 4), one AVX register in the AVX2 build (`bench decode
    // --runs 1` under callgrind, predicted_normals: elephant_1m 154.9 -> 152.2 M instructions).
    for (size_t v = 0; v < plain.size(); v += 2) {
      Float8 two;
      std::memcpy(&two, &plain[v], sizeof two);
      two += two;
      std::memcpy(&sum[v], &two, sizeof two);
    }
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
      const uint32_t a = indices[i] - base, b = indices[i + 1] - base, c = indices[i + 2] - base;
      if (!all_inside && (a >= V || b >= V || c >= V)) continue;
      // Loaded once: for all the compiler knows, the stores to sum may alias them.
      const NormalSum pa = plain[a], pb = plain[b], pc = plain[c];
      const NormalSum t = pa + pb + pc;
      sum[a] += t - pa, sum[b] += t - pb, sum[c] += t - pc;
    }
  };
  if (first_vertex == 0 && index_end == V) {
    accumulate(std::true_type{});
    if (smooth) smoothen(std::true_type{});
  } else {
    accumulate(std::false_type{});
    if (smooth) smoothen(std::false_type{});
  }
}

std::vector<uint64_t> normal_residuals(std::span<const glm::vec3> normals, std::span<const uint32_t> order,
                                       std::span<const NormalSum> sum, uint32_t bits, uint32_t& width) {
  const size_t V = order.size();
  std::vector<uint64_t> residuals(2 * V);
  uint64_t largest = 0;
  const float scale = frame_scale(bits), offset = rounding_offset(bits);
  for (size_t i = 0; i < V; i += 4) {  // sum holds a multiple of 4 entries
    Float4 x, y, z;
    transpose(&sum[i], x, y, z);
    const Frame<Float4> f = prediction_frame(x, y, z);
    for (size_t l = 0; l < 4 && i + l < V; ++l) {
      const glm::vec3 n = normals[order[i + l]];
      auto dot = [&](const Float4(&axis)[3]) {
        return n.x * axis[0][l] + n.y * axis[1][l] + n.z * axis[2][l];
      };
      const glm::ivec2 code = oct_encode(glm::vec3(dot(f.t), dot(f.b), dot(f.p)), scale, offset);
      for (int a = 0; a < 2; ++a) {
        residuals[2 * (i + l) + a] = zigzag(code[a]);
        largest = std::max(largest, residuals[2 * (i + l) + a]);
      }
    }
  }
  width = bytes_for(largest);
  return residuals;
}

NormalCodes code_normals(std::span<const glm::vec3> normals, std::span<const uint32_t> order,
                         std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t index_end,
                         const glm::vec3* positions, uint32_t bits) {
  const uint32_t V = uint32_t(order.size());
  std::vector<NormalSum> sum;
  NormalCodes best;
  uint64_t fewest = UINT64_MAX;
  for (bool smooth : {false, true}) {
    predicted_normals(indices, first_vertex, index_end, positions, V, smooth, sum);
    NormalCodes c;
    c.codes = normal_residuals(normals, order, sum, bits, c.width), c.smooth = smooth;
    uint64_t bits_taken = 0;
    for (uint64_t code : c.codes) bits_taken += std::bit_width(code);
    if (bits_taken < fewest) fewest = bits_taken, best = std::move(c);
  }
  return best;
}

namespace {

// The lanes of x, y, z (Float4, Float8 or Float16) as 4, 8 or 16 normals (3 floats each) at out: in each
// 128-bit lane, three rows (x0 y0 z0 x1) (y1 z1 x2 y2) (z2 x3 y3 z3) of its 4 vertices, each row's 16 bytes
// copied out of its register as they are (one lane extract, to memory), where a Float4 built from the row's 4
// floats took GCC a shuffle a float in 16 lanes and more in 8 (rdtsc around decode_predicted_normals over
// the nodes of refined_elephant and elephant_1m: AVX2 build 5.0 -> 4.4 ticks a vertex).
template <class V>
[[gnu::always_inline]] inline void store_normals(V x, V y, V z, glm::vec3* out) {
  const V xy = in_lanes<0, 4, 1, 5>(x, y), yz = in_lanes<3, 5, 3, 5>(xy, z),
          high = in_lanes<2, 6, 3, 7>(x, y);
  const V rows[3] = {in_lanes<0, 1, 4, 2>(xy, z), in_lanes<0, 1, 4, 5>(yz, high),
                     in_lanes<6, 2, 3, 7>(high, z)};
  for (size_t h = 0; h < sizeof(V) / sizeof(Float4); ++h)
    for (int k = 0; k < 3; ++k) {
      std::memcpy(reinterpret_cast<char*>(out + 4 * h) + sizeof(Float4) * k,
                  reinterpret_cast<const char*>(&rows[k]) + sizeof(Float4) * h, sizeof(Float4));
    }
}

// The codes r[0 .. lanes) as an Int4, Int8 or Int16: codes of a valid node are below 2^16, hostile ones are
// clamped to +-2^18 first (oct_decode clamps them again).
template <class I>
[[gnu::always_inline]] inline I clamped_codes(const int32_t* r) {
  const I limit = I{} + (1 << 18);
  I v;
  std::memcpy(&v, r, sizeof v);
  v = v < -limit ? -limit : v;
  return v > limit ? limit : v;
}

// The normals of N steps of 4 (Float4, Int4), 8 (Float8, Int8) or 16 (Float16, Int16) vertices from their
// sums (sum[0 ..
// N * lanes)) and codes u (first components) and v: each code decoded in its prediction's frame, written to
// out[0 .. N * lanes). Each phase (transposes, frames, decodes, rotations into the frames) is written for
// all N steps before the next, so that the next step's square roots and divisions enter the out-of-order
// window while the first step's chain is still in flight (a step is one chain of 2 square roots and 3
// divisions; consecutive steps written one after the other barely overlapped).
template <class F, class I, size_t N>
[[gnu::always_inline]] inline void decode_steps(const NormalSum* sum, const int32_t* u_codes,
                                                const int32_t* v_codes, float inv_scale, glm::vec3* out) {
  constexpr size_t lanes = sizeof(F) / sizeof(float);
  F px[N], py[N], pz[N], u[N], w[N], h[N];  // the prediction, the normal in its frame
  Frame<F> f[N];
  for (size_t k = 0; k < N; ++k) transpose(&sum[lanes * k], px[k], py[k], pz[k]);
  for (size_t k = 0; k < N; ++k) f[k] = prediction_frame(px[k], py[k], pz[k]);
  for (size_t k = 0; k < N; ++k)
    oct_decode(clamped_codes<I>(&u_codes[lanes * k]), clamped_codes<I>(&v_codes[lanes * k]), inv_scale, u[k],
               w[k], h[k]);
  for (size_t k = 0; k < N; ++k) {
    const F x = u[k] * f[k].t[0] + w[k] * f[k].b[0] + h[k] * f[k].p[0],
            y = u[k] * f[k].t[1] + w[k] * f[k].b[1] + h[k] * f[k].p[1],
            z = u[k] * f[k].t[2] + w[k] * f[k].b[2] + h[k] * f[k].p[2];
    store_normals(x, y, z, &out[lanes * k]);
  }
}

// The V normals from their sums and code planes, L vertices a step (F, I: Float4 and Int4, Float8 and Int8 or
// Float16 and Int16), four steps interleaved, then single steps of 16, 8 and 4: their sums transposed to
// lanes, their frames built, the codes decoded in them, transposed back into 3 floats each. Four steps
// interleaved, where two took 3.7 ticks a vertex in the AVX-512 build and 4.7 in the AVX2 one, four 3.5 and
// 4.5 (rdtsc as at store_normals, both variants in one process, the machine slower than there): a step's
// chain of square roots and divisions is long, and the registers four steps spill cost less than the latency
// they hide. sum holds a multiple of 4 entries; residual and normals take the last step's spare lanes,
// dropped at the end (written in place: a reused `normals` is zero-filled only where it grows, where decoding
// into scratch copied every normal, refined_elephant's bench decode 0.9 M of memcpy).
template <class F, class I>
[[gnu::always_inline]] inline void decode_normals(std::span<const NormalSum> sum, uint32_t V,
                                                  const uint8_t* planes, uint32_t width, uint32_t bits,
                                                  std::vector<glm::vec3>& normals) {
  constexpr size_t L = sizeof(F) / sizeof(float);
  const size_t lanes = (size_t(V) + 3) & ~size_t(3);
  thread_local std::vector<int32_t> residual;
  grow_scratch(residual, 2 * size_t(V) + 4);
  normals.resize(lanes);
  glm::vec3* const out = normals.data();
  read_planes(planes, V, 2, width, residual.data());
  const float inv_scale = 1.0f / frame_scale(bits);
  size_t i = 0;
  for (; i + 4 * L <= lanes; i += 4 * L)
    decode_steps<F, I, 4>(&sum[i], &residual[i], &residual[V + i], inv_scale, &out[i]);
  if constexpr (L == 16)
    for (; i + 16 <= lanes; i += 16)
      decode_steps<Float16, Int16, 1>(&sum[i], &residual[i], &residual[V + i], inv_scale, &out[i]);
  if constexpr (L >= 8)
    for (; i + 8 <= lanes; i += 8)
      decode_steps<Float8, Int8, 1>(&sum[i], &residual[i], &residual[V + i], inv_scale, &out[i]);
  for (; i < lanes; i += 4)
    decode_steps<Float4, Int4, 1>(&sum[i], &residual[i], &residual[V + i], inv_scale, &out[i]);
  normals.resize(V);
}

// The AVX-512 (x86-64-v4) build: 16 vertices a step, 3.3 ticks a vertex where the AVX2 build takes 4.2 (rdtsc
// as at store_normals; this EPYC divides and takes square roots of 16 lanes as fast as of 8). Without FMA
// contraction (CMakeLists.txt's -ffp-contract=off: x86-64-v4 includes FMA), so the same bits as the others.
__attribute__((target("arch=x86-64-v4"))) void decode_normals_avx512(std::span<const NormalSum> sum,
                                                                     uint32_t V, const uint8_t* planes,
                                                                     uint32_t width, uint32_t bits,
                                                                     std::vector<glm::vec3>& normals) {
  decode_normals<Float16, Int16>(sum, V, planes, width, bits, normals);
}

// An AVX2 build: 8 vertices a step, where 4 a step took more instructions for the frames and decodes (`bench
// decode --runs 1` under callgrind, decode_node: refined_elephant 45.80 -> 45.49 M, elephant_1m 687.9 ->
// 682.8 M).
__attribute__((target("avx2"))) void decode_normals_avx2(std::span<const NormalSum> sum, uint32_t V,
                                                         const uint8_t* planes, uint32_t width, uint32_t bits,
                                                         std::vector<glm::vec3>& normals) {
  decode_normals<Float8, Int8>(sum, V, planes, width, bits, normals);
}

}  // namespace

// 4 lanes a step, one SSE register: GCC compares vectors wider than the target's one float at a time (8 lanes
// took 37 ticks a vertex, 4 take 11; rdtsc as at store_normals).
void decode_predicted_normals_baseline(std::span<const NormalSum> sum, uint32_t V, const uint8_t* planes,
                                       uint32_t width, uint32_t bits, std::vector<glm::vec3>& normals) {
  decode_normals<Float4, Int4>(sum, V, planes, width, bits, normals);
}

void decode_predicted_normals(std::span<const NormalSum> sum, uint32_t V, const uint8_t* planes,
                              uint32_t width, uint32_t bits, std::vector<glm::vec3>& normals) {
  call_widest_build(decode_normals_avx512, decode_normals_avx2, decode_predicted_normals_baseline, sum, V,
                    planes, width, bits, normals);
}

}  // namespace lodstream::package
