// Connectivity as a traversal of the triangles across their edges, so that every triangle but the first of
// each connected piece arrives attached to a known edge of the decoded part (Rossignac 1999, "Edgebreaker:
// Connectivity Compression for Triangle Meshes", IEEE TVCG 5(1); here in the form of a front of edges
// processed first in, first out, as Ponchio's Corto codec does). The decoder then knows, for every new
// vertex, the triangle across the edge it was attached to: the parallelogram prediction (Touma & Gotsman
// 1998) needs no search.
//
// The front: loops of half-edges (a -> b) of decoded triangles whose other side is not decoded yet, each loop
// chained (an edge's b is the next edge's a) and each edge knowing o, the third corner of its triangle. Edges
// are processed in the order they were created (the "gate"); for gate a -> b with loop neighbours
// P = (p -> a) and N = (b -> n), one symbol (a byte) says what lies across it:
//   kVertex:   triangle (b, a, c) with c a new vertex (the next number); the gate becomes a -> c, c -> b.
//              c's position is predicted as a + b - o (the parallelogram).
//   kLeft:     triangle (b, a, p); P and the gate become p -> b (requires a loop of 3 edges or more).
//   kRight:    triangle (b, a, n); the gate and N become a -> n (likewise).
//   kEnd:      triangle (b, a, p) closes a loop of exactly 3 edges; the loop is gone.
//   kSplit:    triangle (b, a, c) with c an earlier vertex that is neither p nor n (a reference follows);
//              the gate becomes a -> c, c -> b.
//   kBoundary: nothing across (a border of the node, or a triangle already decoded from another edge); the
//              edge stays in its loop, done.
// When no edge is left to process and triangles remain, a new piece starts with a triangle of three
// references (varint 0 = a new vertex, r > 0 = the vertex r below the next new one) whose edges form a new
// loop; its new vertices are predicted from the vertex before them (the first vertex of all from cmin).
// References of splits are varints r = (next new vertex - 1 - vertex). Vertices no triangle uses come last,
// each predicted from the vertex before it.
//
// Records of several clusters (NodeGeometry::cluster_triangles; C clusters, C <= 31): the traversal runs
// over the whole record as over one mesh, and each triangle's cluster is tagged: untagged when it is the
// cluster of the gate's triangle, else tagged with code 1 + its cluster (format 12: bits 3-7 of the symbol
// byte; format 13: a tagged class, then the code's move-to-front rank); a piece start's references begin
// with a varint cluster. The encoder moves the triangles into the clusters' ranges after the traversal, in
// traversal order within each (a counting sort); the decoder puts each triangle straight into its cluster's
// range (known from the counts), so a decoded record's cluster c is a consecutive range.
// Measured on elephant_1m (bake, codec 3, records of mixed precision): 5,382,094 B, level-0 connectivity
// 0.25 B/tri after zstd; the tags cost 4.7 % (5,142,369 B untagged, which cannot be split back into
// clusters); a first version that kept each cluster's triangles together in the traversal (deferring gates
// into later clusters, no tags) gave 5,689,401 B, its connectivity 0.38 B/tri: it breaks the regular symbol
// runs zstd finds.
//
// Ranked symbols (format 12; format 13 codes the kind itself under the same gate context, below): bits 0-2
// of a symbol byte held not the kind but its rank in the gate's context, the kinds ordered by their
// frequency after gates a -> b where a lies in min(t_a, 7) and b in min(t_b, 7) decoded triangles (t
// counted as the triangles arrive, by encoder and decoder alike; a fixed table of 64 orders). A vertex that
// already holds most of a fan's triangles is about to close it (the valence insight of Touma & Gotsman 1998
// and Alliez & Desbrun 2001, "Valence-driven connectivity encoding for 3D meshes"): at level 0 of
// refined_elephant a gate (2, 5) turns right 98 % of the time, a gate (4, 3) takes a new vertex 97 %, a gate
// (5, 1) turns left 86 %, a gate (6, 6) is a border 100 %. The page's symbol coder (format 12; gone in 13)
// then codes ranks, mostly 0, under the previous rank. Measured offline first (order-0 entropy of the
// classes, aggregated per level, table costs not counted; the table learnt on horse and motorBike): under the
// previous class, then the previous rank, then (t_a, t_b) alone, bits a symbol: refined_elephant level
// 0 1.558 / 0.871 / 0.742, levels >= 1 2.253 / 2.104 / 1.890; bunny 1.865 / 1.308 / 1.220 and 2.226 / 2.183
// / 1.983. Packages, format 11 -> 12
// (`lodstream bake --json`; decoded nodes and 1 px renders identical): refined_elephant 256,618 -> 247,049 B
// (-3.7 %; level-0 connectivity 0.25 -> 0.16 B a stored triangle, levels 1-2 0.38 / 0.43 -> 0.35 / 0.42),
// elephant_1m 2,898,959 -> 2,808,434 (-3.1 %), elephant_5m 11,027,977 -> 10,705,624 (-2.9 %), motorBike
// 1,409,394 -> 1,377,952 (-2.2 %), bunny 242,819 -> 237,429 (-2.2 %), horse 312,104 -> 305,860 (-2.0 %).
// The decoder's cost: a byte counter per vertex, three increments a triangle and two table look-ups a
// symbol, about 22 instructions a triangle with the loop's extra register pressure (`bench decode --runs 1`
// under callgrind, decode_node + read_page: refined_elephant 62.15 -> 65.48 M, +5.4 %; elephant_1m 958.2 ->
// 1,004.5 M, +4.8 %; decode_traversal 15.83 -> 19.27 M and 191.4 -> 238.4 M). Tried: the context by min()
// 19.90 M; counters that saturate at 7 21.10 M; 16-bit counters 20.41 M; each front edge carrying its
// first vertex's wedge (no per-vertex array) 19.45 M for 247,901 B; contexts modulo 8 19.27 M for 247,694 B.
//
// Symbols decoded in the traversal (format 13): a record's symbols are one rANS stream (rans.hpp) under
// fixed tables (traversal_tables.hpp: no tables stored, none built per page), each gate's class (kind, and
// whether its triangle is tagged) coded under the context (previous class, min(t_a, 7), min(t_b, 7)) in
// the table set the stream names (learnt on level 0 or above) and a tagged class followed by its cluster
// code's move-to-front rank (format 8's scheme): the decoder picks the context's row of cumulative
// frequencies, finds the class by comparing the slot with all 16 at once and takes one rANS step, no division
// and no page pass. Measured offline first (tables learnt on horse and motorBike, cross-entropy at 2^12,
// format 11's traversals): refined_elephant 0.871 -> 0.784 bits a symbol at level 0 and 2.104 -> 1.799 above
// (format 12: ranks under the previous rank, per page); bunny 1.308 -> 1.142 and 2.183 -> 1.877 (tag ranks
// not counted). Figures of the packages: traversal_tables.hpp. Decode (`bench decode --runs 1` under
// callgrind, decode_node + read_page): refined_elephant 63.47 -> 64.55 M instructions (+1.7 %), elephant_1m
// 968.5 -> 1,005.6 M (+3.8 %): the page pass is gone (SymbolDecoder 5.2 M and 83.8 M) but decode_traversal
// takes ~45 instructions a gate where it took ~18 with the symbol bytes decoded (19.7 -> 27.1 M, 238.4 ->
// 368.8 M; the extra live state costs spills in the front's stores too). Wall (10 interleaved `bench decode
// --runs 9` of refined_elephant, load 5.4 on 2 cores, medians): format 12 20.90, one rANS state 21.16, two
// 21.73 M triangles/s.
//
// On a manifold patch about half the symbols are kVertex and most others kLeft / kRight / kBoundary (border
// edges). Levels >= 1 cost about twice level 0's bits per triangle (elephant_1m, format 6: 0.44-0.50 against
// 0.25 B/tri after zstd): 1.25-1.45 symbols a triangle against 1.11 (kBoundary 0.25-0.45 against 0.11: the
// borders of smaller, irregular clusters), kSplit 0.05 against 0.001, and kLeft and kRight about even where
// level 0 turns right (0.43 kRight, 0.01 kLeft: less predictable). Decode: O(T), no search, no hash.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace lodstream::package {

enum TraversalSymbol : uint8_t { kVertex = 0, kLeft = 1, kRight = 2, kBoundary = 3, kSplit = 4, kEnd = 5 };

// Gate contexts count at most this many triangles at each of the gate's two vertices.
inline constexpr uint32_t kRankedTriangles = 7;

// A gate as coded: its class (kind, plus 6 when tagged), its context (traversal_tables.hpp) and, tagged, the
// rank of its cluster code among the recent ones (move-to-front, starting from 1..31).
struct TraversalStep {
  uint16_t context;
  uint8_t symbol_class, rank;
};

// The context of a gate after a gate of class `previous` (0 for the first), whose vertices lie in the given
// numbers of decoded triangles (counted modulo 2^8, as the codec counts them). Cost: O(1).
uint32_t traversal_context(uint32_t previous, uint32_t triangles_at_a, uint32_t triangles_at_b);

// The rANS stream of `steps` under table set `set` (0 or 1, traversal_tables.hpp), empty for no steps: two
// interleaved states (step i on state i mod 2), u32 LE each, then u16 LE reads; its first step names the
// set, then each gate's class and a tagged class's rank. Cost: O(steps), a division a step.
std::vector<uint8_t> encode_traversal_steps(std::span<const TraversalStep> steps, uint32_t set);

struct TraversalCode {
  std::vector<uint8_t> symbols;      // the steps' rANS stream (encode_traversal_steps)
  std::vector<TraversalStep> steps;  // one per gate processed
  std::vector<uint8_t> references;   // varints: three per piece start, one per split
  std::vector<uint32_t> order;       // order[decoded vertex] = the input vertex
  std::vector<uint32_t> indices;     // the input's triangles in decoded order and numbering, each rotated
  // Per decoded vertex v, (o1, o2, o): v is predicted as c[o1] + c[o2] - c[o], every corner below v or V
  // (standing for cmin); a single predictor x is (x, x, x).
  std::vector<uint32_t> predictors;
};

// Encodes the triangles `indices` (every index below V). Triangles are found across edges with a per-vertex
// list of outgoing half-edges; a non-manifold edge takes any of its triangles, the others start pieces or
// arrive as splits. `cluster_triangles`: a record's clusters (counts adding up to T, each at least 1, at
// most 31 of them; the input's triangles are their consecutive ranges in order), or empty / one for a single
// cluster. Cost: O(T + V) (times the vertex valence for the look-ups); its scratch (about 50 bytes per corner
// and 8 per vertex) is kept per thread between calls.
// The symbols' stream is the smaller of the two table sets'.
TraversalCode encode_traversal(std::span<const uint32_t> indices, uint32_t V,
                               std::span<const uint32_t> cluster_triangles = {});

// The second parallelogram of the multi-parallelogram prediction (predictive_node.hpp), which the decoder
// learns as it joins triangles: an edge x -> y of triangle (x, y, p) whose other triangle (y, x, q) the
// traversal joins to it (the gate of a kLeft, kRight, kEnd or kSplit, and the loop edge P or N that a kLeft,
// kRight or kEnd closes), with p < q and x, y < q, gives vertex q the parallelogram (x, y, p): c[q] ~ c[x] +
// c[y] - c[p], its corners decoded before q and in the winding of their triangle (the gates of kVertex are
// the predictors themselves). A vertex whose predictor is single (x, x, x: a piece start's) takes its first
// such parallelogram as its predictors instead; the first (next) one found is its second parallelogram, the
// rest are dropped; a vertex without one is predicted from its predictors alone.
struct Parallelograms {
  std::vector<uint32_t> corners;  // per vertex (x, y, p), where found (else left as it was)
  std::vector<uint8_t> found;     // per vertex: whether its second was found
};

// Decodes T triangles of V vertices into indices (3T entries) and predictors (3V entries, as
// TraversalCode's), a record's with the encoder's `cluster_triangles` (which must add up to T, each at least
// 1, at most 31: the caller checks; the decoded triangles of each cluster then form its range); every
// symbol, reference, cluster and vertex count is checked: corrupted streams throw lodstream::Error starting
// with `where`. With `extra`, also the second parallelograms above (the predictors of single-predictor
// vertices replaced as said). Cost: O(T + V), one pass over the symbols; its scratch (the front, up to 96
// bytes a triangle, and a byte a vertex) is kept per thread between calls.
void decode_traversal(std::span<const uint8_t> symbols, std::span<const uint8_t> references, uint32_t T,
                      uint32_t V, uint32_t* indices, uint32_t* predictors, const std::string& where,
                      std::span<const uint32_t> cluster_triangles = {}, Parallelograms* extra = nullptr);

}  // namespace lodstream::package
