#include "package/traversal_connectivity.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/quantized_node.hpp"
#include "package/rans.hpp"
#include "package/traversal_tables.hpp"

namespace lodstream::package {

namespace {

constexpr uint32_t kNone = UINT32_MAX;

// The front of traversal_connectivity.hpp, shared by encoder and decoder so that both apply the same rules.
class Front {
 public:
  // 32 bytes (aligned), its loop neighbours as addresses: a gate reads them with no index to scale, and
  // the front needs no base register (decode_traversal over every record of a package under callgrind,
  // against indices into the storage: elephant_1m 335.4 -> 303.3 M instructions, refined_elephant 24.3 ->
  // 22.0 M; paired timings of the same, new / old, elephant_1m 0.95).
  struct alignas(32) Edge {
    uint32_t a, b, o;
    uint32_t cluster;  // of its triangle (records of several clusters; 0 otherwise)
    Edge *prev, *next;
  };
  // The callers process the gates in order, each once, so the edges below the gate need no mark: only an
  // edge that a kLeft, kRight or kEnd takes out of its loop before its turn does, kTaken in its o (a field
  // nothing reads once the edge is out). No state field to store in every new edge and every processed
  // gate: `bench decode --runs 1` under callgrind, decode_traversal 211.0 -> 200.7 M instructions
  // (elephant_1m), 16.99 -> 16.35 M (refined_elephant).
  static constexpr uint32_t kTaken = kNone;

  // Edges for a front, kept per thread between calls, as calloc's memory: zero where it comes fresh from
  // the system, with no pass over it (a vector's resize zero-filled and copied its edges as it grew: 0.84 M
  // instructions of refined_elephant's `bench decode --runs 1`), and initialized all the same: gate() reads
  // the edge at end().
  class Storage {
   public:
    Edge* reserve(size_t n) {
      if (capacity_ < n) {
        block_.reset(std::calloc(n + 1, sizeof(Edge)));  // one more for the alignment
        if (!block_) throw std::bad_alloc();
        capacity_ = n;
      }
      const uintptr_t at = reinterpret_cast<uintptr_t>(block_.get()) + alignof(Edge) - 1;
      return reinterpret_cast<Edge*>(at & ~uintptr_t(alignof(Edge) - 1));
    }

   private:
    struct Free {
      void operator()(void* p) const { std::free(p); }
    };
    std::unique_ptr<void, Free> block_;
    size_t capacity_ = 0;
  };

  // A front for T triangles in `storage`: a piece start adds 3 edges, every other triangle at most 2: no
  // more than 3T edges, whatever the symbols; gate() reads one more. Its top lives in the Front, a local of
  // the caller, so that the compiler keeps it in a register.
  Front(Storage& storage, size_t triangles) : first_(storage.reserve(3 * triangles + 1)), top_(first_) {}
  // The first edge, where the callers' gates start.
  Edge* first() const { return first_; }
  // The first edge at or after e still in its loop (edges are processed in creation order), or end() when
  // none is. The bound is tested only for a taken edge (the storage's edge at end(), of no meaning, is
  // read): one test and branch fewer a gate (bound first: elephant_1m's decode_traversal 288.8 -> 293.7 M
  // instructions, callgrind as above). The scan's test is predictable where it matters: on elephant_1m every
  // kRight's next gate skips its N (the gate's pair from a kVertex, 99.7 %), the gates after other kinds 7 %.
  // Skipping without a branch was slower (decode_traversal over every record of elephant_1m, main d470041,
  // callgrind and paired thread-CPU times new / old): the first taken edge by a conditional add here, 286.1
  // -> 304.3 M instructions, 1.066 (the next gate's loads wait on this one's o); a kRight's N when it is the
  // next edge, 293.5 M, 1.004.
  Edge* gate(Edge* e) const {
    while (e->o == kTaken && e < top_) ++e;
    return e;
  }
  Edge* end() const { return top_; }
  // p of the gate's kLeft, n of its kRight (kNone unless its loop has 3 edges or more), and whether its loop
  // has exactly 3 (kEnd).
  static uint32_t left(const Edge& g) { return g.prev != g.next ? g.prev->a : kNone; }
  static uint32_t right(const Edge& g) { return g.prev != g.next ? g.next->b : kNone; }
  static bool closes(const Edge& g) { return g.prev != g.next && g.next->next == g.prev; }

  // The new triangle's edges get its cluster k.
  void start(uint32_t v0, uint32_t v1, uint32_t v2, uint32_t k) {
    Edge* const to = top_;
    to[0] = {v0, v1, v2, k, to + 2, to + 1};
    to[1] = {v1, v2, v0, k, to, to + 2};
    to[2] = {v2, v0, v1, k, to + 1, to};
    top_ += 3;
  }
  // kVertex and kSplit: the gate a -> b becomes a -> c, c -> b.
  // The two new edges stored through one address (elephant_1m's decode_traversal 358.0 -> 353.7 M
  // instructions, `bench decode --runs 1` under callgrind: ~3 a kVertex).
  void attach(const Edge& g, uint32_t c, uint32_t k) {
    const uint32_t a = g.a, b = g.b;
    Edge *const prev = g.prev, *const next = g.next, *const to = top_;
    to[0] = {a, c, b, k, prev, to + 1};
    to[1] = {c, b, a, k, to, next};
    top_ += 2;
    prev->next = to;  // a loop has 2 edges or more: prev and next are not the gate
    next->prev = to + 1;
  }
  // kLeft: P = p -> a and the gate become p -> b.
  void close_left(const Edge& g, uint32_t k) {
    Edge& p = *g.prev;
    link(p.prev, g.next, p.a, g.b, g.a, k);
    p.o = kTaken;
  }
  // kRight: the gate and N = b -> n become a -> n.
  void close_right(const Edge& g, uint32_t k) {
    Edge& n = *g.next;
    link(g.prev, n.next, g.a, n.b, g.b, k);
    n.o = kTaken;
  }
  // kEnd: the loop of 3 is gone.
  static void close_loop(const Edge& g) { g.prev->o = g.next->o = kTaken; }

 private:
  // A new edge a -> b (third corner o) between `before` and `after`.
  void link(Edge* before, Edge* after, uint32_t a, uint32_t b, uint32_t o, uint32_t k) {
    Edge* const x = top_++;
    *x = {a, b, o, k, before, after};
    before->next = x;
    after->prev = x;
  }

  Edge* first_;
  Edge* top_;
};

void put_varint(std::vector<uint8_t>& out, uint32_t v) {
  for (; v >= 0x80; v >>= 7) out.push_back(uint8_t(v | 0x80));
  out.push_back(uint8_t(v));
}

constexpr uint32_t kKinds = 6, kScale = 1u << kTraversalScaleBits;

// By a vertex's triangle count t (a byte): 16 x 8 min(t, 7) and 16 x min(t, 7), the offsets of a gate's
// row of class_starts() from its level's and previous class's first row, for the gate's first and
// second vertex (two loads where a min took four instructions with its constant: refined_elephant's
// decode_traversal 19.90 -> 19.27 M instructions, format 12). The min by a compare and a conditional move
// again, 2 cycles where a load takes 4-5 on the way to the class (main 18b25c4, decode_traversal over every
// record, paired thread-CPU times new / old): motorBike 69.17 -> 72.34 M instructions, 0.986 (15 pairs)
// then 1.002 (30), elephant_1m 0.976 then 0.992, refined_elephant 0.925 then 0.984; `bench/decode-pairs` on
// motorBike 0.990 (M triangles/s new / old): within the noise.
struct GateOffsets {
  uint16_t first[256], second[256];
};
constexpr GateOffsets kGateOffsets = [] {
  GateOffsets t{};
  for (uint32_t c = 0; c < 256; ++c)
    t.first[c] = uint16_t(16 * 8 * std::min(c, kRankedTriangles)),
    t.second[c] = uint16_t(16 * std::min(c, kRankedTriangles));
  return t;
}();

// The cluster codes 1..31, most recently coded first (and a byte of padding, 0): a code is stored as its
// rank here (0..30), then moves to the front; every record starts from kFirstClusterCodes.
using RecentClusterCodes = std::array<uint8_t, 32>;
constexpr RecentClusterCodes kFirstClusterCodes = {1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11,
                                                   12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22,
                                                   23, 24, 25, 26, 27, 28, 29, 30, 31, 0};

// Move-to-front (Bentley, Sleator, Tarjan & Wei 1986, "A locally adaptive data compression scheme", CACM
// 29(4)) over the recent cluster codes: the code of rank r < 31, which then moves to the front. Cost: a few
// instructions for r < 16 (most ranks: the codes of bytes 0..r of one or two little-endian words move up a
// byte, without a loop), about 20 above (four words). Measured (format 12's page symbol pass, `bench decode
// --runs 1` under callgrind, read_page): a byte loop for every rank from 8 took elephant_1m 257.20 M
// instructions, refined_elephant 15.50 M (~180 a rank above 16, 14,172 of them in elephant_1m), these 255.92
// / 15.37. No call (a memmove above 16 was one), so that the decoder's loop holds none.
inline __attribute__((always_inline)) uint32_t to_front(RecentClusterCodes& recent, uint32_t r) {
  const uint8_t code = recent[r];
  if (r < 8) [[likely]] {
    uint64_t word;
    std::memcpy(&word, recent.data(), 8);
    const uint64_t moved = ~uint64_t(0) >> (56 - 8 * r);  // bytes 0..r
    word = (word & ~moved) | ((word << 8) & moved) | code;
    std::memcpy(recent.data(), &word, 8);
    return code;
  }
  if (r < 16) {
    uint64_t word[2];
    std::memcpy(word, recent.data(), 16);
    const uint64_t moved = ~uint64_t(0) >> (56 - 8 * (r - 8));  // bytes 8..r
    word[1] = (word[1] & ~moved) | (((word[1] << 8) | (word[0] >> 56)) & moved);
    word[0] = (word[0] << 8) | code;
    std::memcpy(recent.data(), word, 16);
    return code;
  }
  uint64_t word[4];
  std::memcpy(word, recent.data(), 32);
  // Bytes 16..r: of word 2 (all of it from r = 23) and of word 3 (from r = 24; byte 31 is the padding).
  const uint64_t moved2 = r >= 23 ? ~uint64_t(0) : ~uint64_t(0) >> (56 - 8 * (r - 16));
  const uint64_t moved3 = r >= 24 ? ~uint64_t(0) >> (56 - 8 * (r - 24)) : 0;
  word[3] = (word[3] & ~moved3) | (((word[3] << 8) | (word[2] >> 56)) & moved3);
  word[2] = (word[2] & ~moved2) | (((word[2] << 8) | (word[1] >> 56)) & moved2);
  word[1] = (word[1] << 8) | (word[0] >> 56);
  word[0] = (word[0] << 8) | code;
  std::memcpy(recent.data(), word, 32);
  return code;
}

// Every context's row of class starts (traversal_tables.hpp), at kTraversalContexts set + context: the
// distinct rows expanded once (48 KB), so that a gate's row is one address computation from its context,
// with no look-up of its row number on the decoder's path.
struct ClassStarts {
  alignas(64) uint16_t row[2 * kTraversalContexts][16];
};
const uint16_t (*class_starts())[16] {
  static const ClassStarts rows = [] {
    ClassStarts t;
    for (uint32_t c = 0; c < 2 * kTraversalContexts; ++c)
      std::memcpy(t.row[c], kTraversalDistinctRows[kTraversalRowOfContext[c]], sizeof t.row[c]);
    return t;
  }();
  return rows.row;
}

// The cluster ranks' decode table (rans.hpp's fill_slots entries, shift 16) and each slot's rank, and each
// rank's start, from kClusterRankFrequencies (built once: 20 KB).
struct RankTable {
  uint32_t slot[kScale];
  uint8_t rank[kScale];
  uint16_t start[kClusterRanks];
};
const RankTable& rank_table() {
  static const RankTable table = [] {
    RankTable t;
    for (uint32_t r = 0, at = 0; r < kClusterRanks; at += kClusterRankFrequencies[r++]) {
      const uint32_t f = kClusterRankFrequencies[r];
      t.start[r] = uint16_t(at);
      rans::fill_slots(t.slot + at, f, f, 16);
      std::memset(t.rank + at, int(r), f);
    }
    return t;
  }();
  return table;
}

// One rANS step (Duda 2013, eq. 9: D(x) = (s, f_s floor(x / 2^12) + x mod 2^12 - start_s)) under the class
// row `starts` (class_starts()): s is the class whose range holds the slot x mod 2^12, found by
// comparing the slot with all 16 starts at once (the lanes whose start lies above it: the first is s + 1,
// lanes 12-15 always); then x is read back up to kLow from the next 2 bytes at `at` (rans::renormalize).
// Cost: 28 instructions on x86-64, two loads of the row, no branch. There one asm block: GCC 12 took ~37
// for the same steps from intrinsics (copies of x and `at` around renormalize's asm, the class index
// sign-extended and moved): `bench decode --runs 1` under callgrind, decode_traversal, refined_elephant
// 27.95 -> 25.40 M instructions, elephant_1m 370.9 -> 367.0 M. The read by a branch (`at` then waits on no
// step) was slower, presumably mispredicted (no counters on this VM; main 18b25c4, decode_traversal over
// every record, paired thread-CPU times new / old): motorBike 69.17 -> 65.34 M instructions, 1.060;
// elephant_1m 286.1 -> 270.4 M, 1.070; refined_elephant 1.024.
inline __attribute__((always_inline)) uint32_t decode_class(uint32_t& x, const uint16_t* starts,
                                                            const uint8_t*& at) {
  // (AddressSanitizer sees no access in an asm block: its builds take the C++ form, whose reads it checks.)
#if defined(__x86_64__) && !defined(__SANITIZE_ADDRESS__)
  uint64_t above, slot, t, u;  // above: s + 1; t, u: scratch
  __m128i v, low, high;
  asm("movl %k[x], %k[slot]\n\t"
      "andl %[mask], %k[slot]\n\t"
      // The slot in every lane (below 2^15: the signed compare is the unsigned one); the lanes above it.
      "movd %k[slot], %[v]\n\t"
      "punpcklwd %[v], %[v]\n\t"
      "pshufd $0, %[v], %[v]\n\t"
      "movdqu (%[row]), %[low]\n\t"
      "movdqu 16(%[row]), %[high]\n\t"
      "pcmpgtw %[v], %[low]\n\t"
      "pcmpgtw %[v], %[high]\n\t"
      "packsswb %[high], %[low]\n\t"
      "pmovmskb %[low], %k[above]\n\t"
      "tzcntl %k[above], %k[above]\n\t"  // (bsf where there is no BMI1: the same for the nonzero mask)
      // x = (start_{s+1} - start_s) (x >> 12) + slot - start_s
      "movzwl -2(%[row],%[above],2), %k[u]\n\t"
      "movzwl (%[row],%[above],2), %k[t]\n\t"
      "subl %k[u], %k[t]\n\t"
      "subl %k[u], %k[slot]\n\t"
      "shrl %[bits], %k[x]\n\t"
      "imull %k[t], %k[x]\n\t"
      "addl %k[slot], %k[x]\n\t"
      // x < kLow: x = x << 16 | the next u16 and at += 2
      "movzwl (%[at]), %k[t]\n\t"
      "movl %k[x], %k[u]\n\t"
      "shll $16, %k[u]\n\t"
      "orl %k[t], %k[u]\n\t"
      "leaq 2(%[at]), %[t]\n\t"
      "cmpl %[low_state], %k[x]\n\t"
      "cmovbl %k[u], %k[x]\n\t"
      "cmovbq %[t], %[at]"
      : [x] "+r"(x), [at] "+r"(at), [above] "=&r"(above), [slot] "=&r"(slot), [t] "=&r"(t), [u] "=&r"(u),
        [v] "=&x"(v), [low] "=&x"(low), [high] "=&x"(high)
      : [row] "r"(starts), "m"(*reinterpret_cast<const uint16_t(*)[16]>(starts)),
        "m"(*reinterpret_cast<const uint8_t(*)[2]>(at)), [mask] "i"(kScale - 1),
        [bits] "i"(kTraversalScaleBits), [low_state] "i"(rans::kLow)
      : "cc");
  return uint32_t(above) - 1;
#else
  const uint32_t slot = x & (kScale - 1);
  uint32_t c = 0;
  while (starts[c + 1] <= slot) ++c;
  const uint32_t start = starts[c];
  x = (starts[c + 1] - start) * (x >> kTraversalScaleBits) + slot - start;
  uint16_t next;
  std::memcpy(&next, at, 2);
  rans::renormalize(x, at, next);
  return c;
#endif
}

// The cluster rank's step likewise, under rank_table().
inline __attribute__((always_inline)) uint32_t decode_rank(uint32_t& x, const RankTable& table,
                                                           const uint8_t*& at) {
  const size_t slot = x & (kScale - 1);
  x = rans::step(x, table.slot, slot, kTraversalScaleBits);
  uint16_t next;
  std::memcpy(&next, at, 2);
  rans::renormalize(x, at, next);
  return table.rank[slot];
}

// Writes the triangles `from` (3 indices each) into `to` in the clusters' ranges, in their order within each
// cluster; false when the clusters' triangle counts differ from `cluster_triangles`. Cost: O(T).
bool sort_by_cluster(const uint32_t* from, uint32_t* to, std::span<const uint8_t> cluster_of,
                     std::span<const uint32_t> cluster_triangles) {
  thread_local std::vector<uint32_t> at;
  at.assign(cluster_triangles.size() + 1, 0);
  for (uint8_t k : cluster_of) ++at[k + 1];  // k < cluster_triangles.size(), checked by the callers
  for (size_t k = 0; k < cluster_triangles.size(); ++k) {
    if (at[k + 1] != cluster_triangles[k]) return false;
    at[k + 1] += at[k];
  }
  for (size_t t = 0; t < cluster_of.size(); ++t) {
    uint32_t* x = to + 3 * size_t(at[cluster_of[t]]++);
    x[0] = from[3 * t], x[1] = from[3 * t + 1], x[2] = from[3 * t + 2];
  }
  return true;
}

}  // namespace

uint32_t traversal_context(uint32_t previous, uint32_t triangles_at_a, uint32_t triangles_at_b) {
  return 64 * previous +
         (kGateOffsets.first[uint8_t(triangles_at_a)] + kGateOffsets.second[uint8_t(triangles_at_b)]) / 16;
}

std::vector<uint8_t> encode_traversal_steps(std::span<const TraversalStep> steps, uint32_t set) {
  if (steps.empty()) return {};
  const RankTable& ranks = rank_table();
  const uint16_t(*const rows)[16] = class_starts() + kTraversalContexts * set;
  // The coding steps in the decoder's order (start and frequency): the set, then each gate's class and a
  // tagged class's rank; then rANS last step first, step i on state i mod 2.
  std::vector<std::array<uint32_t, 2>> coded = {{kScale / 2 * set, kScale / 2}};
  for (const TraversalStep& s : steps) {
    const uint16_t* row = rows[s.context];
    coded.push_back({row[s.symbol_class], uint32_t(row[s.symbol_class + 1] - row[s.symbol_class])});
    if (s.symbol_class >= kKinds) coded.push_back({ranks.start[s.rank], kClusterRankFrequencies[s.rank]});
  }
  std::vector<uint8_t> reversed;
  uint32_t x[2] = {rans::kLow, rans::kLow};
  for (size_t i = coded.size(); i-- > 0;)
    rans::encode(x[i % 2], coded[i][0], coded[i][1], kTraversalScaleBits, reversed);
  ByteWriter w;
  w.u32(x[0]), w.u32(x[1]);
  w.bytes.insert(w.bytes.end(), reversed.rbegin(), reversed.rend());
  return std::move(w.bytes);
}

TraversalCode encode_traversal(std::span<const uint32_t> indices, uint32_t V,
                               std::span<const uint32_t> cluster_triangles) {
  const uint32_t T = uint32_t(indices.size() / 3);
  const bool clustered = cluster_triangles.size() > 1;
  // Scratch kept per thread between calls (a bake encodes thousands of records on each core): allocated and
  // cleared once rather than per record.
  thread_local std::vector<uint8_t> cluster_of, emitted_cluster, encoded;  // by input triangle; emitted
  thread_local std::vector<uint32_t> first, fill, decoded, traversal_order;
  thread_local std::vector<uint8_t> triangles_at;  // by vertex number: triangles emitted at it (wrapping)
  // Per outgoing half-edge of a vertex, in vertex order: the vertex it goes to, the third corner of its
  // triangle and the triangle (corner c = 3t + k goes from indices[c] to the next corner of t); the look-up
  // across a gate then compares the first field and reads the others, with no division by 3.
  struct HalfEdge {
    uint32_t to, third, triangle;
  };
  thread_local std::vector<HalfEdge> half_edges;
  cluster_of.assign(T, 0);
  for (uint32_t c = 0, t = 0; c < cluster_triangles.size(); ++c)
    for (uint32_t k = 0; k < cluster_triangles[c] && t < T; ++k) cluster_of[t++] = uint8_t(c);
  TraversalCode code;
  // Every triangle is emitted once and every vertex numbered once (the traversal's, then the unused ones):
  // the outputs are written in place at their final sizes.
  code.indices.resize(indices.size());
  code.order.resize(V);
  code.predictors.resize(3 * size_t(V));
  first.assign(size_t(V) + 1, 0);
  for (uint32_t i : indices) ++first[i + 1];
  for (uint32_t v = 0; v < V; ++v) first[v + 1] += first[v];
  fill.assign(first.begin(), first.end() - 1);
  half_edges.resize(indices.size());
  for (uint32_t t = 0; t < T; ++t) {
    const uint32_t* c = &indices[3 * size_t(t)];
    half_edges[fill[c[0]]++] = {c[1], c[2], t};
    half_edges[fill[c[1]]++] = {c[2], c[0], t};
    half_edges[fill[c[2]]++] = {c[0], c[1], t};
  }
  encoded.assign(T, 0);
  decoded.assign(V, kNone);  // decoded[input vertex] = its number
  uint32_t next = 0;         // the next vertex number
  auto add_vertex = [&](uint32_t input, uint32_t o1, uint32_t o2, uint32_t o) {
    decoded[input] = next;
    code.order[next] = input;
    uint32_t* p = &code.predictors[3 * size_t(next)];
    p[0] = o1, p[1] = o2, p[2] = o;
    return next++;
  };
  // Triangles in traversal order: straight into the result, or for a record into a buffer that is then
  // sorted by cluster.
  if (clustered) traversal_order.resize(indices.size()), emitted_cluster.resize(T);
  uint32_t* const out = clustered ? traversal_order.data() : code.indices.data();
  uint32_t done = 0;  // triangles emitted
  triangles_at.assign(V, 0);
  auto emit = [&](uint32_t a, uint32_t b, uint32_t c, uint8_t k) {
    ++triangles_at[a], ++triangles_at[b], ++triangles_at[c];
    uint32_t* x = out + 3 * size_t(done);
    x[0] = a, x[1] = b, x[2] = c;
    if (clustered) emitted_cluster[done] = k;
    ++done;
  };

  thread_local Front::Storage edges;
  Front front(edges, T);
  uint32_t scan = 0;               // triangles below it are encoded
  Front::Edge* e = front.first();  // the gate
  uint32_t previous = 0;           // the previous gate's class
  RecentClusterCodes recent = kFirstClusterCodes;
  while (done < T) {
    e = front.gate(e);
    if (e == front.end()) {
      while (encoded[scan]) ++scan;
      encoded[scan] = 1;
      const uint8_t k = cluster_of[scan];
      if (clustered) put_varint(code.references, k);
      uint32_t corner[3];
      for (int k = 0; k < 3; ++k) {
        const uint32_t input = indices[3 * scan + k];
        if (decoded[input] != kNone) {
          put_varint(code.references, next - decoded[input]);
          corner[k] = decoded[input];
        } else {
          put_varint(code.references, 0);
          const uint32_t from = k > 0 ? corner[k - 1] : next > 0 ? next - 1 : V;
          corner[k] = add_vertex(input, from, from, from);
        }
      }
      front.start(corner[0], corner[1], corner[2], k);
      emit(corner[0], corner[1], corner[2], k);
      continue;
    }
    const Front::Edge g = *e;
    const uint32_t context = traversal_context(previous, triangles_at[g.a], triangles_at[g.b]);
    // The gate's step: class `kind` (+ 6 with the rank of cluster k's code when k is not the gate's).
    auto step = [&](TraversalSymbol kind, uint32_t k) {
      uint8_t symbol_class = kind, rank = 0;
      if (k != g.cluster) {
        symbol_class += kKinds;
        rank = uint8_t(std::find(recent.begin(), recent.begin() + 31, k + 1) - recent.begin());
        to_front(recent, rank);
      }
      code.steps.push_back({uint16_t(context), symbol_class, rank});
      previous = symbol_class;
    };
    // The triangle across a -> b holds half-edge b -> a.
    const uint32_t a_in = code.order[g.a], b_in = code.order[g.b];
    const HalfEdge* across = nullptr;
    for (uint32_t i = first[b_in]; i < first[b_in + 1]; ++i) {
      const HalfEdge& h = half_edges[i];
      if (h.to == a_in && !encoded[h.triangle]) {
        across = &h;
        break;
      }
    }
    if (!across) {
      step(kBoundary, g.cluster);
      ++e;  // the gate stays in its loop, processed
      continue;
    }
    encoded[across->triangle] = 1;
    const uint8_t k = cluster_of[across->triangle];
    const uint32_t c_in = across->third;
    uint32_t c = decoded[c_in];
    if (c == kNone) {
      step(kVertex, k);
      c = add_vertex(c_in, g.a, g.b, g.o);
      front.attach(g, c, k);
    } else if (front.closes(g) && c == front.left(g)) {
      step(kEnd, k);
      front.close_loop(g);
    } else if (c == front.left(g)) {
      step(kLeft, k);
      front.close_left(g, k);
    } else if (c == front.right(g)) {
      step(kRight, k);
      front.close_right(g, k);
    } else {
      step(kSplit, k);
      put_varint(code.references, next - 1 - c);
      front.attach(g, c, k);
    }
    emit(g.b, g.a, c, k);
    ++e;  // the gate is out of its loop
  }
  for (uint32_t v = 0; v < V; ++v) {
    if (decoded[v] != kNone) continue;
    const uint32_t from = next == 0 ? V : next - 1;
    add_vertex(v, from, from, from);
  }
  if (clustered)
    sort_by_cluster(traversal_order.data(), code.indices.data(), std::span(emitted_cluster.data(), T),
                    cluster_triangles);
  // The smaller stream of the two table sets (traversal_tables.hpp).
  code.symbols = encode_traversal_steps(code.steps, 0);
  std::vector<uint8_t> other = encode_traversal_steps(code.steps, 1);
  if (other.size() < code.symbols.size()) code.symbols = std::move(other);
  return code;
}

namespace {

// The decoder's error for a corrupted traversal: out of line, cold and noreturn, so that the decode loop
// holds none of the message's set-up.
[[noreturn, gnu::noinline, gnu::cold]] void corrupted(const std::string& where, const char* what) {
  throw Error(where + ": corrupted connectivity (" + what + ")");
}

// decode_traversal, with the further parallelograms when `multi` (a template constant: none of their work
// without them).
template <bool multi>
void decode_symbols(std::span<const uint8_t> symbols, std::span<const uint8_t> references, uint32_t T,
                    uint32_t V, uint32_t* indices, uint32_t* predictors, const std::string& where,
                    std::span<const uint32_t> cluster_triangles, Parallelograms* extra) {
  ByteReader refs(references, where);
  thread_local Front::Storage edges;
  Front front(edges, T);
  uint32_t next = 0;  // the next new vertex
  // The symbols' rANS stream (encode_traversal_steps), copied with 8 bytes of padding: a gate reads at most 4
  // bytes, and a loop step of two gates starts only at or before the stream's end (one test a step, not one
  // a gate: `bench decode --runs 1` under callgrind, the traversal's decode 337.3 -> 332.9 M instructions on
  // elephant_1m, 24.31 -> 24.04 M on refined_elephant; a stream that ends early is refused at the step after,
  // or for what its padding decodes to). An empty stream holds no gate (`in` past its end).
  // Two states, each step on the one the step before did not take (x, then y: the loop below): a gate's
  // state is not the previous gate's, whose decode only picks its context's row, so that the steps of
  // consecutive gates overlap in the CPU.
  // GCC 12 keeps x, y and `in` on the stack in the gate loop (a load and a store each a gate): register
  // pressure, not the calls (with the kSplit's varint call taken out they stay; -fira-region=one,
  // -fira-algorithm=priority, -fsched-pressure change nothing). On the AMD EPYC of main 18b25c4 the round
  // trip costs no measurable time (decode_traversal over every record, paired thread-CPU times new / old,
  // motorBike and elephant_1m): `in` in a register (a and b as size_t, the counts' base hidden from CSE in
  // emit) 0.998 and 1.006, motorBike 69.17 -> 69.42 M instructions; one scratch register fewer in
  // decode_class and kSplit [[unlikely]] (the spills unchanged) 0.994 and 1.005. Both states in one 64-bit
  // register (each step on the low half, then shrd $32: the other state continues, no swap after a rank)
  // were slower, 1.169 (motorBike) and 1.128 (refined_elephant), 70.54 M: each step then waits on the one
  // before it, the two states no longer overlap.
  // More states gain nothing: two already keep the chain off the critical path (main 780dbcf, a format 15
  // tried, packages baked by each binary, paired thread-CPU times new / old of `bench decode --runs 9`,
  // decoded nodes and 1 px renders identical). Each gate's steps on state g mod N (a rank on its class's
  // state; two so 0.985 against main): four against two 0.999 and 0.988 on motorBike, 0.981 elephant_1m,
  // 0.997 refined_elephant; three against two 0.997 (motorBike). Step i on state i mod 4, the four rotated
  // after a rank: 0.971 against main on motorBike, 0.966 refined_elephant, decode_traversal 69.45 -> 74.63 M
  // instructions (callgrind). Four states cost +0.12-0.18 % of the packages (refined_elephant 225,155 ->
  // 225,453 B). A gate's time goes to its row (the front's a and b, their counts and offsets, the row's
  // loads) and the class search before the kind's branch resolves (perf annotate of motorBike's decode): the
  // front's chain, not the states'.
  thread_local std::vector<uint8_t> stream;
  static constexpr uint8_t kNoStream[1] = {};
  uint32_t x = 0, y = 0;
  const uint8_t *in = kNoStream + 1, *end = kNoStream;  // the next rANS read, and the stream's end
  if (!symbols.empty()) {
    if (symbols.size() < 8) corrupted(where, "symbol stream shorter than its states");
    rans::copy_padded(symbols, stream);
    std::memcpy(&x, stream.data(), 4), std::memcpy(&y, stream.data() + 4, 4);
    if (x < rans::kLow || y < rans::kLow) corrupted(where, "invalid symbol state");
    in = stream.data() + 8, end = stream.data() + symbols.size();
  }
  const RankTable& ranks = rank_table();
  RecentClusterCodes recent = kFirstClusterCodes;
  // The rows of the stream's table set (its first step, at 1/2 each: the slot's top bit), and the offset of
  // the previous class's (times 16 u16 a row).
  const uint16_t(*const all_rows)[16] = class_starts();
  const uint16_t* set_rows = all_rows[0];
  if (in <= end) {
    const uint32_t slot = x & (kScale - 1), set = slot >> (kTraversalScaleBits - 1);
    x = kScale / 2 * (x >> kTraversalScaleBits) + slot - kScale / 2 * set;
    uint16_t bits;
    std::memcpy(&bits, in, 2);
    rans::renormalize(x, in, bits);
    std::swap(x, y);
    set_rows = all_rows[kTraversalContexts * set];
  }
  // The offset of the previous class's rows, 64 bits: added to a pointer with no extension (one instruction
  // a gate: elephant_1m's decode_traversal 288.8 -> 286.1 M, over every record under callgrind).
  size_t previous = 0;
  // Clusters of a record: each triangle goes straight to the next free place in its cluster's range of
  // `indices` (the ranges are consecutive, in cluster order, sized by `cluster_triangles`), so the triangles
  // of each cluster stay in traversal order, as the encoder's counting sort leaves them; C = 1 otherwise
  // (every symbol's cluster code must then be 0).
  const uint32_t C = cluster_triangles.size() > 1 ? uint32_t(cluster_triangles.size()) : 1;
  if (C > kMaxRecordClusters) corrupted(where, "more clusters than a record may hold");
  std::array<uint32_t*, kMaxRecordClusters> at, range_end;  // per cluster: next place, end of its range
  size_t placed = 0;                                        // triangles of the clusters before k
  for (uint32_t k = 0; k < C; ++k) placed += C > 1 ? cluster_triangles[k] : T;
  if (placed != T) corrupted(where, "triangles per cluster differ from the header's");
  placed = 0;
  for (uint32_t k = 0; k < C; ++k) {
    at[k] = indices + 3 * placed;
    placed += C > 1 ? cluster_triangles[k] : T;
    range_end[k] = indices + 3 * placed;
  }
  // Per vertex, the triangles decoded at it (wrapping at 2^8, as the encoder counts them), zeroed a record
  // and incremented. Each new vertex's count set to 1 by its triangle instead (no zeroing, no load for a
  // kVertex's corner) was slower (elephant_1m's decode_traversal, main d470041): stored in the kinds'
  // branches, 286.1 -> 304.0 M instructions, paired times 1.037; carried past them to one store, 301.8 M.
  thread_local std::vector<uint8_t> triangles_at;
  triangles_at.assign(V, 0);
  uint8_t* const count = triangles_at.data();
  // Triangle (v0, v1, v2) of cluster k < C into its range (every corner below V: checked as decoded).
  auto emit = [&](uint32_t v0, uint32_t v1, uint32_t v2, uint32_t k) {
    ++count[v0], ++count[v1], ++count[v2];
    uint32_t*& out = at[k];
    if (out == range_end[k]) corrupted(where, "triangles per cluster differ from the header's");
    out[0] = v0, out[1] = v1, out[2] = v2;
    out += 3;
  };
  // The parallelogram of edge x -> y of triangle (x, y, u) joined to triangle (y, x, w), as the triangle of
  // the smaller of u and w in its winding (traversal_connectivity.hpp).
  auto join = [&](uint32_t x, uint32_t y, uint32_t u, uint32_t w) {
    // Tested before the swap, which most joins then skip (refined_elephant's `bench decode --runs 1` under
    // callgrind: decode_symbols<true> 12.92 -> 12.84 M instructions).
    if (std::max(u, w) <= std::max(x, y) || u == w) return;
    if (u > w) std::swap(x, y), std::swap(u, w);  // (x, y, u) the triangle of the smaller
    uint32_t* to = predictors + 3 * size_t(w);
    if (to[0] != to[1]) {  // not single: the second parallelogram, unless found
      if (extra->found[w]) return;
      extra->found[w] = 1, to = &extra->corners[3 * size_t(w)];
    }
    to[0] = x, to[1] = y, to[2] = u;
  };
  if constexpr (multi) {
    extra->found.assign(V, 0);
    extra->corners.resize(3 * size_t(V));
  }
  Front::Edge* e = front.first();  // the gate
  for (uint32_t left = T; left > 0;) {
    e = front.gate(e);
    if (e == front.end()) {
      uint32_t k = 0;
      if (C > 1) {
        const uint64_t read = refs.varint();
        if (read >= C) corrupted(where, "cluster out of range");
        k = uint32_t(read);
      }
      uint32_t corner[3];
      for (int k = 0; k < 3; ++k) {
        const uint64_t r = refs.varint();
        if (r == 0) {
          if (next == V) corrupted(where, "more vertices than the node holds");
          const uint32_t from = k > 0 ? corner[k - 1] : next > 0 ? next - 1 : V;
          predictors[3 * next] = predictors[3 * next + 1] = predictors[3 * next + 2] = from;
          corner[k] = next++;
        } else {
          if (r > next) corrupted(where, "reference to a vertex not decoded yet");
          corner[k] = next - uint32_t(r);
        }
      }
      front.start(corner[0], corner[1], corner[2], k);
      emit(corner[0], corner[1], corner[2], k);
      --left;
      continue;
    }
    // The gates from here until a piece start, two a loop step: the first one's class on x, the second one's
    // on y (each step on the state the step before did not take), so that the states need no swap but after
    // a tagged class's rank. gate(s, t) decodes the gate e, its class on s, and goes on to the next one, or
    // to front.end() when there is none before a piece start or no triangle is left (where a returned bool
    // took GCC 12 a setne and a test a gate: elephant_1m's decode_traversal over every record under
    // callgrind, 304.6 -> 288.8 M instructions). (In an inner loop, out
    // of the piece starts' one, GCC 12 gave the gate's state fewer stack slots; with the swap in every gate,
    // the states went to the stack: elephant_1m's decode_traversal 353.5 (one loop) -> 344.7 (two) -> 337.8 M
    // instructions (two gates a step), `bench decode --runs 1` under callgrind.)
    auto gate = [&](uint32_t & s, uint32_t & t) __attribute__((always_inline)) {
      const Front::Edge& g = *e;
      const uint32_t a = g.a, b = g.b;
      const uint32_t symbol_class = decode_class(
          s, set_rows + previous + kGateOffsets.first[count[a]] + kGateOffsets.second[count[b]], in);
      // The next gate's row offset (previous) is set in each kind's branch from constants, so that its row
      // waits on the branch (predicted) and not on this class: the chain row load, compare, class, next
      // row (about 18 cycles of latency a gate by the instruction tables) is gone. Paired timings of
      // decode_traversal over every record of elephant_1m, new / old: 0.95 (edges linked by address) -> 0.89
      // (and this), for 1.3 M instructions more.
      // The rest of the row's chain (a and b, their counts, kGateOffsets, the row) made shorter gained
      // nothing (main c761699, decoded nodes and 1 px renders identical; `bench/decode-pairs` on motorBike,
      // 12-16 pairs; decode_symbols<false> under callgrind, 63.7 M instructions before): the next edge's
      // offsets loaded before the kind's branch and used after a kVertex (42 % of the gates; the gate's own
      // two increments moved before the branch, undone by a kBoundary) 1.001, refined_elephant 1.007,
      // elephant_1m 1.010, 78.3 M; after a kBoundary (22 %) 0.991, 74.1 M; its counts kept exact in emit by
      // compares 0.969, 87.9 M; the increments moved alone 0.996, 66.6 M. One load where kGateOffsets took
      // two (a byte min(count, 7) beside each count, both from a table by the count) 1.000, 67.7 M, with the
      // increments moved 0.990, 72.6 M; that byte by a compare in emit 0.987, 68.4 M. Yet the chain counts:
      // two imul by 1 on the row's address 0.967 (0.972 again), on a value nothing waits for 0.990, on the
      // state 0.991.
      uint32_t kind = symbol_class;
      size_t tag = 0;
      // Untagged: the gate's cluster (below C, checked when its triangle was decoded), else the code's - 1.
      uint32_t k = g.cluster;
      if (symbol_class >= kKinds) [[unlikely]] {
        kind -= kKinds, tag = 16 * 64 * kKinds;
        k = to_front(recent, decode_rank(t, ranks, in)) - 1;
        std::swap(s, t);  // the next gate's class on this gate's state
        if (k >= C) corrupted(where, "cluster out of range");
      }
      uint32_t c;
      // kVertex, about half the symbols, tested first. Branch-free forms of this dispatch were slower
      // (refined_elephant's `bench decode`, main 2b2a9a3, callgrind --branch-sim on decode_node, wall as
      // paired new / old ratios of `--runs 50`): kVertex and kRight on one path by conditional moves, 47.8
      // -> 58.7 M instructions, simulated mispredictions 255 -> 205 K, wall 0.92; every kind by conditional
      // moves and tables, 82.0 M, 149 K, wall 0.73. Conditional moves for the cluster code and the gate
      // scan's first step: 48.9 M, 186 K, wall 0.99-1.01 (noise +-1.5 %): the CPU predicts most of what the
      // simulation counts as mispredicted. A switch over the six kinds as a jump table (one indirect branch a
      // gate where the chain's tests may mispredict twice): elephant_1m's decode_traversal 286.1 -> 290.0 M
      // instructions, paired thread-CPU times new / old 1.047 (refined_elephant 1.041), main d470041.
      if (kind == kVertex) {
        previous = tag + 16 * 64 * kVertex;
        if (next == V) corrupted(where, "more vertices than the node holds");
        c = next++;
        // The front first: it reads the gate's fields that a, b were loaded from, and no store lies between.
        const uint32_t o = g.o;
        front.attach(g, c, k);
        uint32_t* const predictor = predictors + 3 * size_t(c);
        predictor[0] = a, predictor[1] = b, predictor[2] = o;
      } else if (kind == kRight) {
        // The others by frequency, a chain of tests (a switch took GCC 12's search by value, 4 tests for a
        // kRight: elephant_1m's decode_traversal 337.8 -> 334.3 M instructions).
        previous = tag + 16 * 64 * kRight;
        c = front.right(g);
        if (c == kNone) corrupted(where, "right turn in a loop of 2");
        if constexpr (multi) join(b, c, g.next->o, a);  // N = b -> c
        front.close_right(g, k);
      } else if (kind == kBoundary) {  // the gate stays in its loop, processed
        previous = tag + 16 * 64 * kBoundary;
        e = front.gate(e + 1);
        return;
      } else if (kind == kLeft) {
        previous = tag + 16 * 64 * kLeft;
        c = front.left(g);
        if (c == kNone) corrupted(where, "left turn in a loop of 2");
        if constexpr (multi) join(c, a, g.prev->o, b);  // P = c -> a
        front.close_left(g, k);
      } else if (kind == kEnd) {
        previous = tag + 16 * 64 * kEnd;
        if (!front.closes(g)) corrupted(where, "end of a loop that is not 3 edges");
        c = front.left(g);
        if constexpr (multi) join(c, a, g.prev->o, b), join(b, c, g.next->o, a);
        front.close_loop(g);
      } else {  // kSplit, the kind left
        previous = tag + 16 * 64 * kSplit;
        const uint64_t r = refs.varint();
        if (r >= next) corrupted(where, "reference to a vertex not decoded yet");
        c = next - 1 - uint32_t(r);
        front.attach(g, c, k);
      }
      if constexpr (multi) {
        if (kind != kVertex) join(a, b, g.o, c);  // the gate (a kVertex's is its predictor)
      }
      emit(b, a, c, k);
      e = --left > 0 ? front.gate(e + 1) : front.end();
    };
    for (;;) {
      // The stream's end, once a loop step: its two gates read at most the padding's 8 bytes past it.
      if (in > end) [[unlikely]]
        corrupted(where, "symbols end early");
      gate(x, y);
      if (e == front.end()) {
        std::swap(x, y);  // the next gate's class on y
        break;
      }
      gate(y, x);
      if (e == front.end()) break;
    }
  }
  if (!symbols.empty()) {
    // Past the end: the last gates decoded from the padding (a stream of fewer symbols than gates).
    if (in > end) corrupted(where, "symbols end early");
    if (in != end || x != rans::kLow || y != rans::kLow) corrupted(where, "symbols left over");
  }
  if (!refs.at_end()) corrupted(where, "references left over");
  for (; next < V; ++next) {
    const uint32_t from = next > 0 ? next - 1 : V;
    predictors[3 * next] = predictors[3 * next + 1] = predictors[3 * next + 2] = from;
  }
}

}  // namespace

void decode_traversal(std::span<const uint8_t> symbols, std::span<const uint8_t> references, uint32_t T,
                      uint32_t V, uint32_t* indices, uint32_t* predictors, const std::string& where,
                      std::span<const uint32_t> cluster_triangles, Parallelograms* extra) {
  if (extra)
    decode_symbols<true>(symbols, references, T, V, indices, predictors, where, cluster_triangles, extra);
  else
    decode_symbols<false>(symbols, references, T, V, indices, predictors, where, cluster_triangles, nullptr);
}

}  // namespace lodstream::package
