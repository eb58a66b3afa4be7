// Entropy coding of a page's zigzagged residuals (byte_planes.hpp: the position and normal residuals of
// codecs 2 and 3), replacing zstd for those page parts (page_parts.hpp). zstd codes a byte plane's bytes with
// a Huffman table, at least one bit per byte: most residuals are tiny (a normal residual is 0 at most
// interior vertices), and their best code is well under a bit. Here each value z is split into a symbol, its
// magnitude class with the bit below the leading one (z for z < 2; else 2 (k - 1) + bit k-2 of z, k the bit
// length of z), and its k - 2 remaining low bits, stored raw. The symbols are coded by rANS (Duda 2013,
// "Asymmetric numeral systems: entropy coding combining speed of Huffman coding with compression rate of
// arithmetic coding", arXiv:1311.2540; 32-bit states renormalized 16 bits at a time, so that a decode step
// reads at most once, without a branch) with one static frequency table per stream, stored in front of it,
// two interleaved states so that the decoder's two dependency chains overlap. No Debian library offers coding
// of our own symbol alphabet with tables of our own (zstd's and lzma's entropy stages are internal to their
// formats), hence this file.
//
// Measured before building it (an offline estimate over every page of the baked packages, each page's model
// alone, table costs included; bench sessions of 2026-12-01, helper "ctxcode"): order-0 coding of these
// symbols takes the positions to 0.93-0.97 and the normals to 0.84-0.90 of their zstd bytes (elephant_1m,
// refined_elephant, motorBike); contexts (axis, predictor kind, the classes of the predicting vertices'
// residuals, the gate edge's length, the other component's class, valence) gained at most 1-2 % more and
// most lost to their tables, so the coder is order 0. Built (format 5), `lodstream bake --json`, format 4 ->
// 5: elephant_5m 21,486,280 -> 20,159,872 B (-6.2 %), elephant_1m -5.2 %, refined_elephant -4.1 %,
// motorBike -3.7 %, city -3.6 %. Its cost is decode time: about 41 instructions a residual (callgrind,
// bench_package BM_Decode/4, decode_node + unpack_page: 382 -> 600 instructions per triangle).
//
// A stream (no bytes for no values): u8 A (symbols in the table, 1..80), A varint frequencies adding up to
// 2^12, varint size of the rANS bytes, the rANS bytes (the two final states first), then the raw bits (LSB
// first, in value order).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace lodstream::package {

// The stream of `values` (zigzagged, each below 2^40). Cost: O(values.size()), two passes.
std::vector<uint8_t> encode_residuals(std::span<const uint64_t> values);

// Reads a stream of encode_residuals back, in the order written, as byte planes. Every table, size, symbol
// and bit read is checked: a corrupted or hostile stream throws lodstream::Error starting with `where`, never
// reads outside its bytes or writes outside the planes asked for.
class ResidualDecoder {
 public:
  // Parses the table. Cost: O(2^12) (the decode table).
  ResidualDecoder(std::span<const uint8_t> stream, const std::string& where);
  // The next count * components values, component by component, as `width` byte planes (put_planes'
  // layout: byte b of component a of value i at planes[(b * components + a) * count + i]); a value needing
  // more than 8 width bytes throws. Cost: O(count * components * width).
  void planes(size_t count, uint32_t components, uint32_t width, uint8_t* planes);
  // Throws unless every byte and bit of the stream was used and the states are back to their start.
  void finish() const;

 private:
  std::string where_;
  // Per slot of 2^12: bits 0-12 its symbol's frequency, 13-24 the slot minus the symbol's start, 25-31 the
  // symbol.
  std::vector<uint32_t> slot_;
  std::span<const uint8_t> rans_, raw_;
  size_t rans_at_ = 0, raw_at_ = 0;
  uint32_t state_[2] = {0, 0};  // the next value's state first
  uint64_t bits_ = 0;           // raw bits buffered, LSB first
  uint32_t bit_count_ = 0;
};

}  // namespace lodstream::package
