#include "package/coarse_positions.hpp"

#include <bit>
#include <cstring>

#include "core/error.hpp"

namespace lodstream::package {

std::vector<uint8_t> encode_locked_stream(const QuantizedNode& node, uint32_t k) {
  std::vector<uint8_t> out;
  if (k == 0) return out;
  const size_t V = node.locked.size();
  out.resize((V + 7) / 8, 0);
  // A locked vertex whose k low bits are all 0 is not flagged: its c (floor and rounding agree) decodes to
  // q as a free vertex's does.
  std::vector<uint8_t> flagged(V, 0);
  for (size_t v = 0; v < V; ++v) {
    for (int a = 0; a < 3; ++a) flagged[v] |= node.locked[v] && node.q[3 * v + a] != node.c[3 * v + a] << k;
    if (flagged[v]) out[v / 8] |= static_cast<uint8_t>(1u << (v % 8));
  }
  size_t bit = 0;
  for (size_t v = 0; v < V; ++v) {
    if (!flagged[v]) continue;
    for (int a = 0; a < 3; ++a) {
      const uint64_t low = static_cast<uint64_t>(node.q[3 * v + a] - (node.c[3 * v + a] << k));
      for (uint32_t b = 0; b < k; ++b, ++bit) {
        if (bit % 8 == 0) out.push_back(0);
        out.back() |= static_cast<uint8_t>(((low >> b) & 1u) << (bit % 8));
      }
    }
  }
  return out;
}

LockedStream LockedStream::parse(std::span<const uint8_t> stream, size_t vertices, uint32_t k,
                                 const std::string& where) {
  LockedStream s{stream, vertices, k};
  if (k == 0) {
    if (!stream.empty()) throw Error(where + ": locked stream without a position shift");
    return s;
  }
  const size_t flag_bytes = (vertices + 7) / 8;
  if (stream.size() < flag_bytes) throw Error(where + ": locked stream too short");
  // Counted 8 flag bytes at a time: the baseline build's popcount is a libgcc call (a call a byte was 1.8
  // instructions a triangle of motorBike's level 3 under callgrind).
  size_t locked_count = 0, i = 0;
  for (uint64_t w; i + 8 <= flag_bytes; i += 8)
    std::memcpy(&w, stream.data() + i, 8), locked_count += std::popcount(w);
  for (; i < flag_bytes; ++i) locked_count += std::popcount(stream[i]);
  if (vertices % 8 && (stream[vertices / 8] >> (vertices % 8)))
    throw Error(where + ": locked bits past the last vertex");
  if (stream.size() != flag_bytes + (locked_count * 3 * k + 7) / 8)
    throw Error(where + ": locked stream size does not match its locked vertices");
  return s;
}

namespace {

using Int64x2 = int64_t __attribute__((vector_size(16)));
using Int32x4 = int32_t __attribute__((vector_size(16)));
using Float32x4 = float __attribute__((vector_size(16)));

// The locked stream's low bits read in vertex order (bit: the next flagged vertex's first).
struct LowBits {
  const uint8_t* flags = nullptr;
  const uint8_t* residuals = nullptr;
  size_t residual_bytes = 0, bit = 0;
  uint32_t k = 0;
  uint64_t mask = 0;

  explicit LowBits(const LockedStream& locked)
      : flags(locked.stream.data()), k(locked.k), mask((uint64_t(1) << locked.k) - 1) {
    const size_t flag_bytes = (locked.vertices + 7) / 8;
    if (k > 0) residuals = flags + flag_bytes, residual_bytes = locked.stream.size() - flag_bytes;
  }
  // Flags of vertices v .. v + 3 (v a multiple of 4, v + 3 < V), bit i for vertex v + i.
  uint32_t four_flags(size_t v) const { return (flags[v / 8] >> (v % 8)) & 15u; }
  bool flagged(size_t v) const { return (flags[v / 8] >> (v % 8)) & 1u; }
  // The next flagged vertex's low bits added to q[0..2] (parse() checked that they exist). A window holds
  // at least 57 bits: x's, y's and z's k <= 19 bits, or x's and y's k <= 24 (z's then from a second).
  void add_next(int64_t* q) {
    const uint64_t xyz = window(bit), z = k <= 19 ? xyz >> (2 * k) : window(bit + 2 * k);
    q[0] += int64_t(xyz & mask), q[1] += int64_t((xyz >> k) & mask), q[2] += int64_t(z & mask);
    bit += 3 * k;
  }

 private:
  // The residual bits from bit `at_bit` on (at least 57; zeros past the stream's end): one unaligned 8-byte
  // load where 8 bytes remain, byte by byte at the stream's end.
  uint64_t window(size_t at_bit) const {
    const size_t at = at_bit / 8;
    uint64_t w = 0;
    if (at + 8 <= residual_bytes)
      std::memcpy(&w, residuals + at, 8);
    else
      for (size_t b = 0; at + b < residual_bytes; ++b) w |= uint64_t(residuals[at + b]) << (8 * b);
    return w >> (at_bit % 8);
  }
};

// positions[v] = origin + float(q) * step, q = c * 2^k + the low bits of a flagged locked vertex (0 for the
// others), for the first V - V % 4 vertices, 4 a step: 12 coordinates as three registers of 4, each from the
// low halves of 4 int64 (one shuffle) converted together (cvtdq2ps, which rounds an integer as the scalar
// conversion does), multiplied, then added (no contraction: the same two roundings as the scalar formula).
// Without kShift (k = 0) q = c; with it, a step of four vertices none of which is flagged shifts c in
// registers, and one with flagged vertices builds its q in 12 int64 of scratch first. Valid only where every
// q lies in [-2^31, 2^31), as those of a valid node do: returns false (the caller then applies the scalar
// formula to all, from the stream's first low bits) when one does not. About 4 instructions a coordinate
// against 8 scalar (callgrind, every node decoded: decode_positions elephant_1m 30.7 -> 19.9 M,
// refined_elephant 2.14 -> 1.51 M). Forced inline into decode_positions' AVX2 build.
template <bool kShift>
[[gnu::always_inline]] inline bool decode_positions_by_four(const int64_t* c, size_t V, LowBits& low,
                                                            const PositionGrid& grid, glm::vec3* positions) {
  const Float32x4 origin[3] = {{grid.origin.x, grid.origin.y, grid.origin.z, grid.origin.x},
                               {grid.origin.y, grid.origin.z, grid.origin.x, grid.origin.y},
                               {grid.origin.z, grid.origin.x, grid.origin.y, grid.origin.z}};
  const Float32x4 step = {grid.step, grid.step, grid.step, grid.step};
  const Int64x2 half = {int64_t(1) << 31, int64_t(1) << 31};
  Int64x2 shifted = {0, 0};  // OR of q + 2^31: below 2^32 while every q fits
  char* out = reinterpret_cast<char*>(positions);
  int64_t scratch[12];
  for (size_t i = 0; i + 4 <= V; i += 4, c += 12, out += 48) {
    const int64_t* q = c;
    uint32_t k = 0;
    if constexpr (kShift) {
      k = low.k;
      if (uint32_t set = low.four_flags(i)) {
        for (int j = 0; j < 12; ++j) scratch[j] = c[j] * (int64_t(1) << k);  // |c| <= 2^32, k <= 24
        for (; set; set &= set - 1) low.add_next(scratch + 3 * std::countr_zero(set));
        q = scratch, k = 0;
      }
    }
#pragma GCC unroll 3
    for (int r = 0; r < 3; ++r) {
      Int64x2 lo, hi;
      std::memcpy(&lo, q + 4 * r, 16), std::memcpy(&hi, q + 4 * r + 2, 16);
      if constexpr (kShift) lo <<= k, hi <<= k;
      shifted |= (lo + half) | (hi + half);
      const Int32x4 q32 = __builtin_shufflevector(Int32x4(lo), Int32x4(hi), 0, 2, 4, 6);
      const Float32x4 p = origin[r] + __builtin_convertvector(q32, Float32x4) * step;
      std::memcpy(out + 16 * r, &p, 16);
    }
  }
  return ((shifted[0] | shifted[1]) >> 32) == 0;
}

}  // namespace

// An AVX2 build besides the baseline one, as predicted_normals (no FMA: the same bits): VEX's 3-operand forms
// (`bench decode --runs 1` under callgrind, decode_node: refined_elephant 44.43 -> 44.32 M instructions,
// elephant_1m 670.1 -> 668.4 M).
// Nodes with a shift (k > 0) take the four-vertex steps too, their flagged locked vertices' low bits added
// in scratch: coarse levels, where most vertices are locked (motorBike's levels 3-5: 64-89 % of them
// flagged), took a scalar pass over every vertex with a branch and a load per locked coordinate (glm's
// indexed axes a switch each). Measured under callgrind, every node of one level decoded (decode_node),
// decode_positions per triangle: motorBike level 3 61.7 -> 33.4 instructions, level 4 80.1 -> 45.4, level
// 0 (k = 0) 5.2 -> 5.3; `bench decode --runs 1`, whole program: motorBike 266.4 -> 264.2 M.
__attribute__((target_clones("avx2", "default"))) void decode_positions(std::span<const int64_t> c,
                                                                        const LockedStream& locked,
                                                                        const PositionGrid& grid,
                                                                        glm::vec3* positions) {
  const size_t V = locked.vertices;
  LowBits low(locked);
  const bool fits = locked.k == 0 ? decode_positions_by_four<false>(c.data(), V, low, grid, positions)
                                  : decode_positions_by_four<true>(c.data(), V, low, grid, positions);
  size_t from = V - V % 4;
  if (!fits) from = 0, low.bit = 0;
  // The formula per axis, named rather than indexed (glm's operator[] is a switch on the axis).
  const float step = grid.step, origin[3] = {grid.origin.x, grid.origin.y, grid.origin.z};
  for (size_t v = from; v < V; ++v) {
    int64_t q[3];
    for (int a = 0; a < 3; ++a) q[a] = c[3 * v + a] * (int64_t(1) << locked.k);
    if (locked.k > 0 && low.flagged(v)) low.add_next(q);
    float* p = &positions[v].x;
    p[0] = origin[0] + static_cast<float>(q[0]) * step;
    p[1] = origin[1] + static_cast<float>(q[1]) * step;
    p[2] = origin[2] + static_cast<float>(q[2]) * step;
  }
}

}  // namespace lodstream::package
