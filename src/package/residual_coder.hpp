// Entropy coding of a page's zigzagged residuals (byte_planes.hpp: the position and normal residuals of
// codecs 2 and 3), replacing zstd for those page parts (page_parts.hpp). zstd codes a byte plane's bytes with
// a Huffman table, at least one bit per byte: most residuals are tiny (a normal residual is 0 at most
// interior vertices), and their best code is well under a bit. Here each value z is a symbol: z itself when
// z < 2^D (a direct value; D, 1..6, chosen per stream), else its bit length k > D (symbol 2^D + k - D - 1)
// followed by its k - 1 bits below the leading one, stored raw. The symbols are coded by rANS (Duda 2013,
// "Asymmetric numeral systems: entropy coding combining speed of Huffman coding with compression rate of
// arithmetic coding", arXiv:1311.2540; 32-bit states renormalized 16 bits at a time, so that a decode step
// reads at most once, with conditional moves rather than a branch) with one static frequency table per
// stream, stored in front of it, and four interleaved states (value i takes state i mod 4) so that the
// decoder's four dependency chains overlap. No Debian library offers coding of our own symbol alphabet with
// tables of our own (zstd's and lzma's entropy stages are internal to their formats), hence this file.
//
// Measured before building it (an offline estimate over every page of the baked packages, each page's model
// alone, table costs included; bench sessions of 2026-12-01, helper "ctxcode"): order-0 coding of these
// symbols takes the positions to 0.93-0.97 and the normals to 0.84-0.90 of their zstd bytes (elephant_1m,
// refined_elephant, motorBike); contexts (axis, predictor kind, the classes of the predicting vertices'
// residuals, the gate edge's length, the other component's class, valence) gained at most 1-2 % more and
// most lost to their tables, so the coder is order 0.
//
// Direct values are for speed: a decode step of one is a table lookup, a multiply and a conditional 16-bit
// read, with no branch; only values of raw bits take a (rarely taken) branch. The encoder estimates the size
// for each D (codes, raw bits, table) and takes the largest D within 0.5 % of the smallest: on the pages of
// bench_package (refined_elephant) that is D = 5-6 for positions and 3-5 for normals, leaving about 1 % of
// the values with raw bits (a D of 1-3 would be up to 1 % smaller and leave 10-70 %, each a mispredicted
// branch). The first form of this coder (every value a class and raw bits, two states, a renormalization
// branch) cost 600 instructions a triangle in BM_Decode/4 against 382 with zstd'd planes; this one ~440
// when both parts are coded (callgrind, decode_node + unpack_page). Packages, format 5 -> 6 (`lodstream bake
// --json`, with page_parts.hpp's 0.2-bit rule): elephant_5m 18,485,383 -> 17,511,877 B (-5.3 %),
// elephant_1m -4.7 %, refined_elephant -2.9 %, motorBike -2.9 %, bunny -2.6 %, horse -2.3 %, city -2.7 %.
//
// A stream (no bytes for no values): u8 D (1..6), u8 A (symbols in the table, 1..2^D + 40 - D), A varint
// frequencies adding up to 2^12, varint size of the rANS bytes, the rANS bytes (the four final states
// first, u32 LE each; then u16 LE reads), then the raw bits (LSB first, in value order).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace lodstream::package {

// The stream of `values` (zigzagged, each below 2^40). Cost: O(values.size()), two passes, and 6 estimates
// over a histogram for D.
std::vector<uint8_t> encode_residuals(std::span<const uint64_t> values);

// Reads a stream of encode_residuals back, in the order written, as byte planes. Every table, size, symbol
// and bit read is checked: a corrupted or hostile stream throws lodstream::Error starting with `where`, never
// reads outside its bytes or writes outside the planes asked for.
class ResidualDecoder {
 public:
  // Parses the table. Cost: O(2^12) (the decode table, 16 KB) and a copy of the stream.
  ResidualDecoder(std::span<const uint8_t> stream, const std::string& where);
  // The next count * taken values, components first .. first + taken - 1 of `components` one after the
  // other, as `width` byte planes (put_planes' layout: byte b of component a of value i at
  // planes[(b * components + a) * count + i]; the other components' planes are left as they are); a value
  // needing more than `width` bytes throws. Cost: O(count * taken * width); about 25 instructions a direct
  // value.
  void planes(size_t count, uint32_t components, uint32_t width, uint8_t* planes, uint32_t first,
              uint32_t taken);
  void planes(size_t count, uint32_t components, uint32_t width, uint8_t* planes) {
    this->planes(count, components, width, planes, 0, components);
  }
  // Throws unless every byte and bit of the stream was used and the states are back to their start.
  void finish() const;

 private:
  [[noreturn]] void fail(const char* what) const;

  std::string where_;
  // Per slot of 2^12 (null for no stream): bits 0-15 its symbol's frequency, 16-31 the slot minus the
  // symbol's start; and apart, its symbol (a step takes each with one instruction: 3 fewer a value than with
  // the symbol in the same word). Allocated without zero-filling: the constructor writes every slot or throws
  // (zero-filling 2^12 slots for every page part took ~0.9 % of elephant_1m's decode instructions). The
  // symbols (2^12 bytes) follow the slots in the same allocation, so that the decode loop reaches both from
  // one register (two took one register too many: the loop reloaded them from the stack, two loads a value).
  std::unique_ptr<uint32_t[]> slot_;
  uint32_t direct_bits_ = 0;  // D
  // The rANS bytes then the raw bits, followed by 8 zero bytes, so that reads a few bytes past the rANS
  // bytes' end stay in the buffer (the decoder checks after each block of 4 values that they were not used)
  // and a raw-bit read is one 8-byte load.
  std::vector<uint8_t> bytes_;
  size_t rans_end_ = 0, rans_at_ = 0;
  uint64_t raw_bit_at_ = 0, raw_bit_end_ = 0;
  uint32_t state_[4] = {0, 0, 0, 0};  // the next value's state first
};

}  // namespace lodstream::package
