// Built-in frequency tables of the paired residual streams (residual_coder.hpp's encode_paired_residuals: a
// page's normal residuals, component 1 coded in the context of the same vertex's component 0), so that such a
// stream stores a set index (one byte) instead of its tables. kSets sets of kContexts tables each: context
// c < 3 is that of a component-1 value whose vertex's component-0 value has a low byte of bit length c (2 for
// 2 or more), context 3 that of the component-0 values. A table holds the frequencies (adding up to 2^12,
// each at least 1) of the kSymbols symbols of residual_coder.hpp with D = kDirectBits direct bits.
//
// Learnt (scripts/learn_paired_tables.py) from the normal residuals of every page of horse and motorBike
// only, never from the meshes the sizes are measured on: the pages' histograms clustered into kSets sets by
// k-means under the code length (each page assigned to the set coding it shortest, each set's tables
// re-estimated from its pages' counts, 10 rounds from a split by mean symbol). Offline estimate against
// format 12's normals (the writer's choice between the paired stream and zstd'd planes, 0.2-bit rule; table
// costs counted): refined_elephant 26,514 -> 24,314 B (-8.3 %), bunny -6.7 %, elephant_1m -5.7 % (393,102 ->
// 370,797). With bit lengths up to 7 told apart (9 contexts) -8.4 / -6.8 / -5.8 %, but at 9 tables a set
// (180 KB) against 4 (80 KB) in the decoder's cache; with 9 contexts and 4 sets -7.0 / -5.9 / -4.3 %, 16 sets
// -8.6 / -7.1 / -6.4 %; with one order-0 table per set and no context +1.3 / +0.6 % (16 sets).
#pragma once

#include <cstdint>

namespace lodstream::package::residual_tables {

inline constexpr uint32_t kSets = 8, kContexts = 4, kDirectBits = 6, kFirstContext = 3;
inline constexpr uint32_t kSymbols = (1u << kDirectBits) + 40 - kDirectBits;  // 98: residual_coder's alphabet

extern const uint16_t kFrequencies[kSets][kContexts][kSymbols];

// The context of a component-1 value whose vertex's component-0 value has low byte `b`: min(bit length, 2).
inline constexpr uint32_t context_of(uint8_t b) {
  return b < 2 ? b : 2;
}

}  // namespace lodstream::package::residual_tables
