// Entropy coding of a page's traversal symbols (traversal_connectivity.hpp) with the previous symbol as
// context, replacing zstd for the connectivity part of a page (page_parts.hpp). zstd's Huffman stage codes
// each symbol byte alone, in one bit at least; the traversal's symbols follow each other in patterns (at
// level 0 of a subdivided scan kVertex and kRight alternate) that the previous symbol predicts.
//
// A symbol byte holds a kind t (bits 0-2: 0..5; since format 12 the kind's rank in its gate's context,
// traversal_connectivity.hpp) and a cluster code g (bits 3-7: 0 for the gate's cluster).
// Each is coded as its class s = t + 6 [g > 0] (12 classes) under the table of the previous symbol's class
// (the page's first symbol: under class 0's), followed when g > 0 by the rank of g among the cluster codes,
// most recently coded first (move-to-front, format 8), under one table of ranks (order 0). rANS (rans.hpp)
// with tables of 2^8 and two interleaved states: coding step i (classes and ranks counted together) takes
// state i mod 2.
//
// Measured before building it (an offline estimate over the pages of the baked packages, each page's tables
// alone, table costs included): connectivity symbols after zstd 893,071 B on elephant_1m (0.25 B/tri at level
// 0, 0.44-0.55 at levels 1-8); classes under the previous class 663,379 and the cluster codes 77,296 (order
// 0; 122,606 as 5 raw bits); the previous two classes as context gained nothing once learnt per page
// (adaptive estimate 662,007 against 651,600 for one), the byte itself as context lost it to its tables.
//
// Tables of 2^8: each page's tables cost bytes and decode time, and 12-class alphabets need little
// precision: elephant_1m 4,001,261 B with 2^10, 3,997,610 with 2^9, 3,996,354 with 2^8, 3,997,483 with 2^7.
//
// Packages, format 6 -> 7 (`lodstream bake --json`, main 067d3fc; pages keep the coded form where it saves
// 0.2 bit a symbol): elephant_5m 15,862,955 -> 15,388,395 B (-3.0 %), elephant_1m 4,153,943 -> 3,996,354
// (-3.8 %; connectivity at level 0 0.25 -> 0.20 B/tri, at level 1 0.48 -> 0.40 with the references),
// refined_elephant -2.9 %, motorBike -1.8 %, bunny -2.3 %, horse -2.5 %, city -1.3 %; decoded pages
// identical. Decode: about 35 instructions a symbol (1.2 symbols a triangle) and 13 tables built per page:
// BM_Decode/4 (bench_package, records of refined_elephant; callgrind, decode_node + unpack_page) 399.5 ->
// 429.6 instructions a triangle (+7.5 %; 446.2 with tables of 2^10).
//
// Cluster codes by rank (format 8): a tag's cluster is usually one that a recent tag named (the traversal
// crosses between the same few clusters of a record for a while), which the order-0 table of codes could
// not see. Measured offline first (elephant_1m, each level's tags as one sequence, order-0 entropy): 2.97
// -> 2.20 bits a code at level 0, 3.10 -> 2.26 at level 1, 19.7 KB in all. Packages (`lodstream bake
// --json`, format 7 -> 8): elephant_5m 15,159,315 -> 15,081,642 B (-0.51 %), elephant_1m 3,939,809 ->
// 3,920,643 (-0.49 %; connectivity at level 0 0.20 -> 0.19 B/stored tri, at level 1 0.37 -> 0.36),
// refined_elephant -0.32 %, motorBike -0.21 %, bunny -0.33 %, horse -0.33 %, city -0.23 %; decoded nodes
// identical. Decode: a whole refined_elephant (`lodstream bench decode`, callgrind, decode_node +
// unpack_page) 70.14 M -> 70.45 M instructions (+0.44 %: about 28 instructions a tagged symbol; 51 with a
// byte loop for every rank; 0.28 M more when forced inline into the symbol loop).
//
// A stream: per context c = 0..11, a u16 LE mask of the classes that follow it (0 for a context that never
// occurs), then the varint frequencies of those classes but the last, which takes the rest of 2^8; a u32
// LE mask of the ranks (bit r) and their frequencies likewise; varint size of the rANS bytes; the rANS
// bytes (the two final states, u32 LE each, then u16 LE reads).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace lodstream::package {

// The cluster codes 1..31, most recently coded first: a code is stored as its rank here (0..30), then moves
// to the front; every stream starts from kFirstClusterCodes.
using RecentClusterCodes = std::array<uint8_t, 31>;
inline constexpr RecentClusterCodes kFirstClusterCodes = {1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11,
                                                          12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22,
                                                          23, 24, 25, 26, 27, 28, 29, 30, 31};

// The stream of `symbols`; nullopt when one is not a traversal symbol (kind 6 or 7), as the connectivity
// bytes of nodes that are no traversal (codec 2's form of codec 3) may be. Cost: O(symbols.size()).
std::optional<std::vector<uint8_t>> encode_symbols(std::span<const uint8_t> symbols);

// Reads a stream of encode_symbols back, in the order written. Every table, size and read is checked: a
// corrupted or hostile stream throws lodstream::Error starting with `where` or decodes to other symbols
// (which the traversal decoder then checks), never reads outside its bytes.
class SymbolDecoder {
 public:
  // Parses the tables. Cost: O(2^8) per table (the decode tables, 1.25 KB each) and a copy of
  // the stream.
  SymbolDecoder(std::span<const uint8_t> stream, const std::string& where);
  // The next `count` symbols into `out`. Cost: O(count), about 31 instructions a symbol.
  void symbols(size_t count, uint8_t* out);
  // Throws unless every byte of the stream was used and the states are back to their start.
  void finish() const;

 private:
  [[noreturn]] void fail(const char* what) const;

  std::string where_;
  // 13 tables of 2^8 slots (12 contexts, then the cluster codes' ranks; null for no stream), each slot: bits
  // 0-15 its symbol's frequency (0 in a table that never occurs), 16-31 the slot minus the symbol's start;
  // and apart, its symbol (as residual_coder.hpp's: no masks to take them apart, elephant_1m's whole decode
  // SymbolDecoder::symbols 96.5 -> 86.3 M instructions). Allocated without zero-filling: the constructor
  // writes every slot or throws.
  std::unique_ptr<uint32_t[]> slot_;
  std::unique_ptr<uint8_t[]> symbol_;
  std::vector<uint8_t> bytes_;  // the rANS bytes, followed by 8 zero bytes (reads past the end stay inside)
  size_t rans_end_ = 0, rans_at_ = 0;
  uint32_t state_[2] = {0, 0};  // the next step's first
  uint32_t context_ = 0;        // the previous symbol's class
  RecentClusterCodes recent_ = kFirstClusterCodes;
};

}  // namespace lodstream::package
