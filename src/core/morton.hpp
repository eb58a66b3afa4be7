// Morton (Z-order) codes: the bits of three integer coordinates interleaved (x in bit 0, y in bit 1, z in bit
// 2, then the next bit of each), so that sorting by the code walks space along a Z curve and points near each
// other in the order are near in space (Morton 1966; the bit spreading of Giesen, "Decoding Morton codes",
// 2009). Header-only: a few shifts and masks per coordinate.
#pragma once

#include <cstdint>

namespace lodstream {

// Bit i of the 10 low bits of `v` moved to bit 3i (the other bits zero).
constexpr uint32_t morton_spread10(uint32_t v) {
  v &= 0x3FF;
  v = (v | (v << 16)) & 0x030000FF;
  v = (v | (v << 8)) & 0x0300F00F;
  v = (v | (v << 4)) & 0x030C30C3;
  v = (v | (v << 2)) & 0x09249249;
  return v;
}

// The 30-bit Morton code of a point of the 1024^3 grid (coordinates' low 10 bits).
constexpr uint32_t morton_code10(uint32_t x, uint32_t y, uint32_t z) {
  return morton_spread10(x) | morton_spread10(y) << 1 | morton_spread10(z) << 2;
}

// Bit i of the 21 low bits of `v` moved to bit 3i (the other bits zero).
constexpr uint64_t morton_spread21(uint64_t v) {
  v &= 0x1FFFFF;
  v = (v | v << 32) & 0x1F00000000FFFFull;
  v = (v | v << 16) & 0x1F0000FF0000FFull;
  v = (v | v << 8) & 0x100F00F00F00F00Full;
  v = (v | v << 4) & 0x10C30C30C30C30C3ull;
  return (v | v << 2) & 0x1249249249249249ull;
}

// The 63-bit Morton code of a point of the 2^21-per-axis grid (coordinates' low 21 bits).
constexpr uint64_t morton_code21(uint32_t x, uint32_t y, uint32_t z) {
  return morton_spread21(x) | morton_spread21(y) << 1 | morton_spread21(z) << 2;
}

}  // namespace lodstream
