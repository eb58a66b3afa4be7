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
// read, with no branch. The encoder estimates the size for each D (codes, raw bits, table) and takes the
// largest D within 0.5 % of the smallest, for fewer values of raw bits (in format 6, on the pages of
// bench_package (refined_elephant): D = 5-6 for positions and 3-5 for normals, about 1 % of the values with
// raw bits, where a D of 1-3 would be up to 1 % smaller and leave 10-70 %), unless they are common anyway
// (below: then the smallest D). The first form of this coder (every value a class and raw bits, two states, a
// renormalization branch) cost 600 instructions a triangle in BM_Decode/4 against 382 with zstd'd planes;
// this one ~440 when both parts are coded (callgrind, decode_node + unpack_page). Packages, format 5 -> 6
// (`lodstream bake --json`, with page_parts.hpp's 0.2-bit rule): elephant_5m 18,485,383 -> 17,511,877 B
// (-5.3 %), elephant_1m -4.7 %, refined_elephant -2.9 %, motorBike -2.9 %, bunny -2.6 %, horse -2.3 %, city
// -2.7 %.
//
// Format 13 (helper "restables", 2026-12-03): a page's normal residuals may also be one paired stream
// (encode_paired_residuals), with no stored tables: component 1 of a vertex is coded with the table of its
// context, the bit length of the low byte of the same vertex's component 0 (decoded before it), from a set of
// built-in tables (residual_tables.hpp, learnt on horse and motorBike) that the encoder chooses per stream.
// Measured first (offline, every page of the format-12 bakes): the stored tables are 0.29-0.48 % of the
// packages (refined_elephant 1,176 B of 243,982: 711 in positions' streams, 465 in normals'; bunny 672 B,
// horse 1,256, motorBike 4,936) but for elephant_1m's 1.06 % (29,233 B in 852 streams, 21,543 of them the
// positions'), and built-in tables without contexts lose more than they save (positions +2.2 %, normals +13.6
// % on refined_elephant with one table; +0.3 / +1.3 % choosing among 16): a page's scale varies. Offered
// beside the stream's own table (the smaller kept per stream), 32 built-in order-0 tables would save 272 B on
// refined_elephant's positions, 1,580 B on elephant_1m's (0.06 %): not built. With contexts: the normals'
// pair gains 6-8 % (sizes in residual_tables.hpp); for the positions, the previous value's class (a
// dependency between the four states' chains) and the other components' gained at most 1 % over today's coder
// (16 sets), nothing was built for them. Packages, format 12 -> 13 (`lodstream bake`): refined_elephant
// 243,982 -> 241,759 B (-0.91 %), bunny 234,933 -> 232,898 (-0.87 %), elephant_1m 2,769,806 -> 2,746,287
// (-0.85 %), elephant_5m 10,550,301 -> 10,515,447 (-0.33 %); the training meshes horse -0.81 %, motorBike
// -0.28 %. Decode (`bench decode --runs 1` under callgrind, whole process): refined_elephant 89.59 -> 90.00 M
// instructions (+0.46 %: a paired component-1 value's context, a load and an add, and the set's 4 tables
// built on first use), elephant_1m 1,072.6 -> 1,074.1 M (+0.13 %). A set's 4 tables (80 KB) do not stay in
// L1 as one table (20 KB) does: the L1 read misses of planes() in refined_elephant's decode, 28.6 k -> 62.7 k
// (cachegrind, its default caches; 71.3 k with 9 contexts).
//
// Values of raw bits (helper "rawbits", 2026-12-03), counted in format 14's whole decodes: refined_elephant
// 41,587 of its 244,459 residuals (17 %), all in its positions' streams (48.6 % of their 85,539 values: split
// form, component 0 at D = 3 (63 % of the values with raw bits) or 5 (24 %), components 1-2 at D = 5 (64 %)
// or 6 (41 %); raw bits 3-7, 8 % of them more), none in its normals (paired, D = 6); elephant_1m 156 k of
// 6.47 M (2.4 %): positions' whole-form streams (D = 4) 0.25 %, split components 0 0.5-1.7 %, components 1-2
// 45 % in 33 streams (D = 5) and 5.6 % in 111 (D = 6), normals 0.08 % (own tables) and none (paired). Each
// took a branch that mispredicts where they are common, so the decoder chooses per stream from its table
// (residual_coder.cpp's raw_bytes_of): the branch where they are rare, else a way without it (the raw bits of
// a block of 4 values from one 8-byte read, per-symbol tables of the bit count, leading one and mask), in one
// byte or, where values of 8 raw bits or more are not rare, two; and the encoder, where they are common,
// takes the smallest D (the decode costs the same). Decode (`bench/decode-pairs`, main c806a13 on its package
// against this on its own, triangles a second): refined_elephant 1.052 and 1.059 (20 pairs each; its pages'
// time, decompress_page, 0.71), motorBike 1.063, horse 1.052, bunny 1.018, elephant_1m 1.004 (12 pairs each);
// instructions (`bench decode --runs 1`, callgrind) refined_elephant 86.77 -> 87.12 M, elephant_1m 1,021.8 ->
// 1,030.4 M (more than with the branch, but no mispredictions). Packages (`lodstream bake`): refined_elephant
// 225,434 -> 225,155 B (-0.12 %), bunny 214,701 -> 213,908 (-0.37 %), horse 280,746 -> 279,849 (-0.32 %),
// motorBike 1,305,234 -> 1,302,988 (-0.17 %), elephant_1m 2,535,327 -> 2,532,569 (-0.11 %), elephant_5m
// 9,838,557 -> 9,829,619 (-0.09 %), city 17,811,588 -> 17,787,740 B (-0.13 %); renders identical.
//
// A stream (no bytes for no values): u8 D (1..6), u8 A (symbols in the table, 1..2^D + 40 - D), A varint
// frequencies adding up to 2^12, varint size of the rANS bytes, the rANS bytes (the four final states
// first, u32 LE each; then u16 LE reads), then the raw bits (LSB first, in value order). A paired stream: u8
// set (below residual_tables::kSets; D is kDirectBits), then the same from the varint size on.
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
// The same with D = direct_bits whatever the values (encode_residuals' choice to compare with). Throws
// lodstream::Error unless 1 <= direct_bits <= 6. Cost: O(values.size()), two passes.
std::vector<uint8_t> encode_residuals(std::span<const uint64_t> values, uint32_t direct_bits);

// The paired stream (residual_coder.hpp) of `values`: per count n of `counts` in turn, n values of component
// 0 then the n of component 1 of the same vertices (a page's normal residuals, node by node), each below
// 2^40; the set is the one whose code lengths add up smallest. Throws lodstream::Error when the counts do not
// add up to the values. Cost: O(values.size()) and O(kSets * kContexts * kSymbols) for the choice, then a
// coding pass.
std::vector<uint8_t> encode_paired_residuals(std::span<const uint64_t> values,
                                             std::span<const uint32_t> counts);

// Reads a stream of encode_residuals (or, paired, of encode_paired_residuals) back, in the order written, as
// byte planes. Every table, size, symbol and bit read is checked: a corrupted or hostile stream throws
// lodstream::Error starting with `where`, never reads outside its bytes or writes outside the planes asked
// for.
class ResidualDecoder {
 public:
  // Parses the table (a paired stream's set when `paired`). Cost: O(2^12) (the decode table, 20 KB; a paired
  // stream's built-in tables once per set and process) and a copy of the stream.
  ResidualDecoder(std::span<const uint8_t> stream, const std::string& where, bool paired = false);
  // The next count * taken values, components first .. first + taken - 1 of `components` one after the
  // other, as `width` byte planes (put_planes' layout: byte b of component a of value i at
  // planes[(b * components + a) * count + i]; the other components' planes are left as they are); a value
  // needing more than `width` bytes throws; a paired stream's only components are 0 and 1 of 2, taken
  // together. Cost: O(count * taken * width); about 25 instructions a direct value, about 30 a value where
  // values of raw bits are common (residual_coder.hpp).
  void planes(size_t count, uint32_t components, uint32_t width, uint8_t* planes, uint32_t first,
              uint32_t taken);
  void planes(size_t count, uint32_t components, uint32_t width, uint8_t* planes) {
    this->planes(count, components, width, planes, 0, components);
  }
  // Throws unless every byte and bit of the stream was used and the states are back to their start.
  void finish() const;

 private:
  [[noreturn]] void fail(const char* what) const;
  // Decodes the next `values` values into planes[0 .. values) (their higher bytes `stride` apart), value at
  // `out` with step_of(x, out) (the rANS step of x with the value's table: returns the symbol and steps x);
  // `largest` is the largest value the planes hold.
  // kRawBytes: raw_bytes_, or 1 where the planes have one byte.
  template <uint32_t kRawBytes, typename StepOf>
  void decode(uint8_t* planes, size_t values, size_t stride, uint64_t largest, StepOf step_of);

  std::string where_;
  bool paired_ = false;
  // The decode table (null for no stream), or a paired stream's set's kContexts compact tables one after
  // the other (residual_coder.cpp's paired_tables). A stream's own table: per slot of 2^12, bits 0-15 its
  // symbol's frequency, 16-31 the slot minus the symbol's start; and apart, its symbol (a step takes each
  // with one instruction: 3 fewer a value than with the symbol in the same word). The symbols (2^12 bytes)
  // follow the slots, so that the decode loop reaches both from one register (two took one register too many:
  // the loop reloaded them from the stack, two loads a value).
  const uint32_t* slots_ = nullptr;
  // The table of a stream with its own, allocated without zero-filling: the constructor writes every slot or
  // throws (zero-filling 2^12 slots for every page part took ~0.9 % of elephant_1m's decode instructions).
  std::unique_ptr<uint32_t[]> own_slots_;
  uint32_t direct_bits_ = 0;  // D
  // How decode takes the stream's values of raw bits (residual_coder.cpp's raw_bytes_of): 0 with a branch,
  // 1 or 2 without one where they fit that many bytes (when the planes have them).
  uint32_t raw_bytes_ = 0;
  // The rANS bytes then the raw bits, followed by 8 zero bytes, so that reads a few bytes past the rANS
  // bytes' end stay in the buffer (the decoder checks after each block of 4 values that they were not used)
  // and a raw-bit read is one 8-byte load.
  std::vector<uint8_t> bytes_;
  size_t rans_end_ = 0, rans_at_ = 0;
  uint64_t raw_bit_at_ = 0, raw_bit_end_ = 0;
  uint32_t state_[4] = {0, 0, 0, 0};  // the next value's state first
};

}  // namespace lodstream::package
