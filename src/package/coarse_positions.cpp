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
  size_t locked_count = 0;
  for (size_t i = 0; i < flag_bytes; ++i) locked_count += std::popcount(stream[i]);
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

// positions[v] = origin + float(c) * step for the first V - V % 4 vertices, 4 a step: 12 coordinates as
// three registers of 4, each from the low halves of 4 int64 (one shuffle) converted together (cvtdq2ps, which
// rounds an integer as the scalar conversion does), multiplied, then added (no contraction: the same two
// roundings as the scalar formula). Valid only where every coordinate lies in [-2^31, 2^31), as those of a
// valid node do: returns false (the caller then applies the scalar formula to all) when one does not. About 4
// instructions a coordinate against 8 scalar (callgrind, every node decoded: decode_positions elephant_1m
// 30.7 -> 19.9 M, refined_elephant 2.14 -> 1.51 M). Forced inline into decode_positions' AVX2 build.
[[gnu::always_inline]] inline bool decode_positions_by_four(const int64_t* c, size_t V,
                                                            const PositionGrid& grid, glm::vec3* positions) {
  const Float32x4 origin[3] = {{grid.origin.x, grid.origin.y, grid.origin.z, grid.origin.x},
                               {grid.origin.y, grid.origin.z, grid.origin.x, grid.origin.y},
                               {grid.origin.z, grid.origin.x, grid.origin.y, grid.origin.z}};
  const Float32x4 step = {grid.step, grid.step, grid.step, grid.step};
  const Int64x2 half = {int64_t(1) << 31, int64_t(1) << 31};
  Int64x2 shifted = {0, 0};  // OR of c + 2^31: below 2^32 while every c fits
  char* out = reinterpret_cast<char*>(positions);
  for (size_t i = 0; i + 4 <= V; i += 4, c += 12, out += 48)
#pragma GCC unroll 3
    for (int r = 0; r < 3; ++r) {
      Int64x2 low, high;
      std::memcpy(&low, c + 4 * r, 16), std::memcpy(&high, c + 4 * r + 2, 16);
      shifted |= (low + half) | (high + half);
      const Int32x4 q = __builtin_shufflevector(Int32x4(low), Int32x4(high), 0, 2, 4, 6);
      const Float32x4 p = origin[r] + __builtin_convertvector(q, Float32x4) * step;
      std::memcpy(out + 16 * r, &p, 16);
    }
  return ((shifted[0] | shifted[1]) >> 32) == 0;
}

}  // namespace

// An AVX2 build besides the baseline one, as predicted_normals (no FMA: the same bits): VEX's 3-operand forms
// (`bench decode --runs 1` under callgrind, decode_node: refined_elephant 44.43 -> 44.32 M instructions,
// elephant_1m 670.1 -> 668.4 M).
__attribute__((target_clones("avx2", "default"))) void decode_positions(std::span<const int64_t> c,
                                                                        const LockedStream& locked,
                                                                        const PositionGrid& grid,
                                                                        glm::vec3* positions) {
  const size_t V = locked.vertices;
  const uint32_t k = locked.k;
  auto position = [&](int a, int64_t q) { return grid.origin[a] + static_cast<float>(q) * grid.step; };
  if (k == 0) {
    const size_t from = decode_positions_by_four(c.data(), V, grid, positions) ? V - V % 4 : 0;
    for (size_t v = from; v < V; ++v)
      for (int a = 0; a < 3; ++a) positions[v][a] = position(a, c[3 * v + a]);
    return;
  }
  const uint8_t* flags = locked.stream.data();
  const uint8_t* residuals = flags + (V + 7) / 8;
  const size_t residual_bytes = locked.stream.size() - (V + 7) / 8;
  const uint64_t mask = (uint64_t(1) << k) - 1;
  size_t bit = 0;
  for (size_t v = 0; v < V; ++v) {
    const bool is_locked = (flags[v / 8] >> (v % 8)) & 1;
    for (int a = 0; a < 3; ++a) {
      int64_t q = c[3 * v + a] * (int64_t(1) << k);
      if (is_locked) {
        // k ≤ 24 bits at bit offset ≤ 7 lie in 4 bytes; parse() checked that they exist. One 4-byte load
        // (little-endian) where 4 bytes remain, byte by byte at the stream's end.
        const size_t at = bit / 8;
        uint64_t window = 0;
        if (at + 4 <= residual_bytes) {
          uint32_t word;
          std::memcpy(&word, residuals + at, 4);
          window = word;
        } else {
          for (size_t b = 0; at + b < residual_bytes; ++b) window |= uint64_t(residuals[at + b]) << (8 * b);
        }
        q += static_cast<int64_t>((window >> (bit % 8)) & mask);
        bit += k;
      }
      positions[v][a] = position(a, q);
    }
  }
}

}  // namespace lodstream::package
