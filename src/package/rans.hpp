// What the package's two rANS coders share (residual_coder.hpp: residuals, traversal_connectivity.hpp:
// traversal symbols): rANS (Duda 2013, "Asymmetric numeral systems: entropy coding combining speed of Huffman
// coding with compression rate of arithmetic coding", arXiv:1311.2540) with 32-bit states kept in [2^16,
// 2^32) and renormalized 16 bits at a time, so that a decode step reads at most once; static frequency tables
// adding up to a power of two.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace lodstream::package::rans {

// The lowest state; every stream starts (encoder) and ends (decoder) with its states at kLow.
inline constexpr uint32_t kLow = 1u << 16;

// Into `frequencies` (as many as `counts`): frequencies adding up to 2^scale_bits, at least 1 for every
// symbol counted, 0 for the others, about proportional to `counts` (which add up to `total` > 0; at most
// 2^scale_bits symbols counted). Cost: O(counts.size()) plus a few passes when rounding overshoots.
void normalize(std::span<const uint32_t> counts, uint64_t total, uint32_t scale_bits,
               std::span<uint32_t> frequencies);

// The encoder's step for a symbol of frequency f starting at `start` of 2^scale_bits (Duda 2013, eq. 9
// inverted: C(s, x) = 2^n floor(x / f_s) + x mod f_s + start_s), first moving 16 bits of x out to `reversed`
// (which the stream stores reversed, read back as u16 LE) when C would leave 32 bits. Steps run last symbol
// first. Cost: a division.
inline void encode(uint32_t& x, uint32_t start, uint32_t f, uint32_t scale_bits,
                   std::vector<uint8_t>& reversed) {
  if (x >= (uint64_t(kLow >> scale_bits) << 16) * f) {
    reversed.push_back(uint8_t(x >> 8)), reversed.push_back(uint8_t(x));
    x >>= 16;
  }
  x = ((x / f) << scale_bits) + x % f + start;
}

// A decode table's run of one symbol: slots[j] = entry | j << shift for j < f, where entry's bits lie apart
// from j << shift's (so that adding the shifted j is or-ing it), four slots a store: GCC 12's -O2 leaves a
// loop of unknown length scalar, and the tables are a fair part of a page's decode (a residual table of 2^12
// slots a page part for ~10^4 values: ~9 instructions a slot scalar, elephant_1m's whole package 28 M);
// eight slots a loop step while they last (the loop's own instructions once for two stores: elephant_1m's
// bench decode, read_page 259.10 -> 257.23 M instructions, callgrind). Cost: O(f).
inline void fill_slots(uint32_t* slots, uint32_t entry, uint32_t f, uint32_t shift) {
  using Four = uint32_t __attribute__((vector_size(16)));
  Four run = Four{0, 1, 2, 3} << shift | entry;
  const Four step = Four{4, 4, 4, 4} << shift;
  uint32_t j = 0;
  for (; j + 8 <= f; j += 8, run += step + step) {
    const Four next = run + step;
    std::memcpy(slots + j, &run, sizeof run), std::memcpy(slots + j + 4, &next, sizeof next);
  }
  for (; j + 4 <= f; j += 4, run += step) std::memcpy(slots + j, &run, sizeof run);
  for (; j < f; ++j) slots[j] = entry | j << shift;
}

// The decoder's step (Duda 2013, eq. 9: D(x) = f_s floor(x / 2^n) + x mod 2^n - start_s) for x's slot
// `slot` (x mod 2^n, plus the table's first slot) of a table of fill_slots entries with shift 16: bits 0-15
// f_s, bits 16-31 the slot minus start_s. The two halves are loaded apart (two loads, where one load then a
// mask and a shift took one instruction more: ResidualDecoder::planes of refined_elephant's whole decode
// 6.61 -> 6.37 M, callgrind); the entry's halves in that order assume a little-endian machine, as the
// streams' u16 LE reads do. Cost: two loads, a multiply.
inline __attribute__((always_inline)) uint32_t step(uint32_t x, const uint32_t* slots, size_t slot,
                                                    uint32_t scale_bits) {
  uint16_t f, below;
  std::memcpy(&f, reinterpret_cast<const uint8_t*>(slots) + 4 * slot, 2);
  std::memcpy(&below, reinterpret_cast<const uint8_t*>(slots) + 4 * slot + 2, 2);
  return f * (x >> scale_bits) + below;
}

// A decoder's copy of its stream: `from` followed by 8 zero bytes (so that a read a few bytes past the end
// stays inside), each byte written once (a zero-filled resize, then the copy, wrote the stream twice:
// elephant_1m's decode 2.3 M instructions). Cost: O(from.size()).
inline void copy_padded(std::span<const uint8_t> from, std::vector<uint8_t>& to) {
  to.reserve(from.size() + 8);
  to.assign(from.begin(), from.end());
  to.resize(from.size() + 8);
}

// The decoder's renormalization: x < kLow: x = x << 16 | next and at += 2, else neither; with conditional
// moves, not a branch (a read comes about every 16 bits of code, every few steps: a branch mispredicts on
// most, and GCC 12 compiles every C form of the selection, hints included, to a branch). `at`: a position
// (size_t) or a pointer to bytes.
template <typename Position>
inline __attribute__((always_inline)) void renormalize(uint32_t& x, Position& at, uint16_t next) {
  const uint32_t read = x << 16 | next;
#if defined(__x86_64__)
  const Position after = at + 2;
  asm("cmpl %[low], %[x]\n\tcmovbl %[read], %[x]\n\tcmovbq %[after], %[at]"
      : [x] "+r"(x), [at] "+r"(at)
      : [read] "r"(read), [after] "r"(after), [low] "i"(kLow)
      : "cc");
#else
  const uint32_t keep = uint32_t(x >= kLow);
  x = read ^ ((read ^ x) & (0 - keep));
  at += 2 - 2 * keep;
#endif
}

}  // namespace lodstream::package::rans
