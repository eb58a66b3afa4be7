// The fixed rANS tables of the traversal's symbols (traversal_connectivity.hpp, format 13): built into the
// code, so that no page or record stores tables and the traversal decodes its symbols itself, one rANS step
// a gate under the table its context picks.
//
// A gate's class s = kind + 6 [tagged] (12 classes; tagged: the triangle's cluster is not the gate's) is
// coded under context (previous class, t_a, t_b): the previous gate's class (0 before the first); min(t, 7)
// for the triangles decoded at the gate's two vertices; in one of two table sets, learnt on the records of
// level 0 and on those above, which the record's stream names first (a step at 1/2: the encoder keeps the
// smaller stream; the decoder knows no level, and a node's position_shift 0 is no level 0: it covers most
// of refined_elephant's level 1 and 2 records too). A tagged class is followed by the move-to-front rank of
// its cluster code (symbol_coder's scheme of format 8) under one order-0 table.
//
// Learnt by bench/learn_traversal_tables.cpp (which prints traversal_tables.cpp; then clang-format) on the
// bakes of horse and motorBike only, never on the meshes the package is measured on (refined_elephant, bunny,
// elephant_*): each context's class counts plus 4 pseudo-counts spread as the context (set, t_a, t_b) without
// the previous class, plus half a count a class, normalized to 2^12 with at least 1 for every class (every
// class stays codable in every context). The tables are part of the format: learning them again changes the
// bytes a bake writes (and the tool reads packages baked with the tables built in; the traversal, and so what
// it learns, does not depend on them: learnt again from its own bakes, the tables come back the same).
//
// Measured (format 12 -> 13, `lodstream bake`; decoded nodes unchanged, 1 px renders of refined_elephant
// and elephant_1m cmp-identical): refined_elephant 243,982 -> 238,914 B (-2.08 %), bunny 234,933 ->
// 227,772 (-3.05 %), horse 302,705 -> 293,382 (-3.08 %, trained on), motorBike 1,369,731 -> 1,341,686
// (-2.05 %, trained on), elephant_1m 2,769,806 -> 2,665,894 (-3.75 %), elephant_5m 10,550,301 ->
// 10,146,163 (-3.83 %). Streams of refined_elephant: 1.03 bits a gate at level 0 (97,944 gates) and 2.18
// above (71,935), tag ranks and states included; elephant_1m 0.88 and 2.20. One table set for every level,
// chosen by position_shift 0 instead: refined_elephant 240,163 B, elephant_1m 2,699,601. Pseudo-counts 1,
// 4 or 16 moved refined_elephant by 10 B.
#pragma once

#include <cstdint>

namespace lodstream::package {

inline constexpr uint32_t kTraversalScaleBits = 12;
inline constexpr uint32_t kTraversalClasses = 12, kTraversalContexts = 12 * 64;
inline constexpr uint32_t kClusterRanks = 31;

// A row: the classes' cumulative frequencies, starts[0] = 0, starts[12..15] = 2^12 (the decoder compares all
// 16 at once); class s has frequency starts[s + 1] - starts[s] >= 1. Each distinct row once (contexts never
// seen in training share their prior's row: 878 rows for 1,536 contexts).
inline constexpr uint32_t kTraversalDistinctRowCount = 878;
extern const uint16_t kTraversalDistinctRows[kTraversalDistinctRowCount][16];
// Per table set (0: learnt on level 0, 1: above) and context (previous class 64 + 8 min(t_a, 7) +
// min(t_b, 7)), at kTraversalContexts set + context: the number of its row in kTraversalDistinctRows.
extern const uint16_t kTraversalRowOfContext[2 * kTraversalContexts];
// The cluster codes' move-to-front ranks' frequencies (add up to 2^12, each >= 1).
extern const uint16_t kClusterRankFrequencies[kClusterRanks];

}  // namespace lodstream::package
