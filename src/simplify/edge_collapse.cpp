// Quadric edge collapse: see simplify.hpp for the operator, framework, vertex kinds, validity rules and the
// two-sided bound. Hand-written: no Debian library offers attribute quadrics with seams, locks and a tracked
// bound (meshoptimizer 0.18 has positions-only half-edge collapse and no bound; OpenMesh's decimater has
// neither seams nor a bound).
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <span>
#include <utility>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/counting_sort.hpp"
#include "core/morton.hpp"
#include "core/representatives.hpp"
#include "simplify/cluster.hpp"
#include "simplify/cost_order.hpp"
#include "simplify/quadric.hpp"
#include "simplify/simplify.hpp"
#include "simplify/uninitialized.hpp"

namespace lodstream::simplify {
namespace {

// The hot paths (place, try_collapse, vertical_bound, add_face, merge) are compiled twice, for x86-64's
// baseline and for AVX2, and the loader picks one for the machine (GCC's function multiversioning, an ifunc):
// with AVX2 the float and double lanes take VEX three-operand forms (fewer register copies) and
// vertical_bound's crossing test four lanes per step. AVX2 does not include FMA, so nothing is fused into a
// multiply-add and both versions compute the same bits (12 simplify outputs and 4 bakes cmp-identical).
// elephant_1m 0.1, whole command, callgrind: 17,380 -> 16,920 M instructions (the collapse), -> 16,597 M
// (add_face); later merge 356.0 -> 311.2 M.
#if defined(__x86_64__) && defined(__GNUC__)
#define LODSTREAM_HOT_PATH __attribute__((target_clones("avx2", "default")))
#define LODSTREAM_RUNS_AVX2() __builtin_cpu_supports("avx2")  // the version the loader picks
#else
#define LODSTREAM_HOT_PATH
#define LODSTREAM_RUNS_AVX2() false
#endif

constexpr uint32_t kNone = UINT32_MAX;
enum Kind : uint8_t { kManifold, kBorder, kSeam, kLocked };

struct Candidate {
  float cost;
  uint32_t a;  // removed
  uint32_t b;  // kept
};

// A face corner's candidate (Simplifier::slots_[3f + k]: the edge from corner k to corner k + 1) in 4 bytes:
// its cost, +inf when there is none, and in the sign bit (costs are >= 0) whether corner k + 1 is the one
// removed. The ends are read from the face when it is tried (Simplifier::listed): a face renamed since the
// evaluation has a touched vertex on that edge, which skips the candidate as the evaluated ends would. A
// third of the bytes of (cost, a, b): the pass's scans of every slot (goal_cost, gather_candidates) read 3x
// less, and elephant_1m holds 34 MB less.
struct Slot {
  uint32_t bits;

  static Slot make(float cost, bool reverse) {
    uint32_t u;
    std::memcpy(&u, &cost, 4);
    return {u | (reverse ? 0x80000000u : 0u)};
  }
  static Slot none() { return make(std::numeric_limits<float>::infinity(), false); }
  uint32_t cost_bits() const { return bits & 0x7fffffffu; }  // order like the costs
  float cost() const {
    const uint32_t u = cost_bits();
    float f;
    std::memcpy(&f, &u, 4);
    return f;
  }
  bool reverse() const { return bits >> 31; }
  bool valid() const { return cost_bits() < 0x7f800000u; }  // a finite cost
};

// f(i) for each slot i in [begin, end) whose cost bits (Slot::cost_bits) lie in [lo, hi], in increasing i
// (hi <= 0x7f7fffff: finite costs only). Four slots a step in vector lanes (SSE2 on x86-64: the bits with
// the sign cleared, two compares, one movemask), and a step with no slot in range is a few instructions:
// the scans of every slot (goal_cost, gather_candidates) tested each slot with two branches before.
template <class F>
void for_slots_in(const Slot* slots, size_t begin, size_t end, uint32_t lo, uint32_t hi, F&& f) {
  size_t i = begin;
#if defined(__SSE2__)
  using Bits = int32_t __attribute__((vector_size(16)));  // the bits are below 2^31: signed compares
  const Bits below = Bits{} + (int32_t(lo) - 1), top = Bits{} + int32_t(hi), magnitude = Bits{} + 0x7fffffff;
  for (; i + 4 <= end; i += 4) {
    Bits bits;
    std::memcpy(&bits, slots + i, sizeof bits);
    bits &= magnitude;
    const Bits in = (bits > below) & (bits <= top);
    for (int mask = _mm_movemask_ps(_mm_castsi128_ps(__m128i(in))); mask != 0; mask &= mask - 1)
      f(i + size_t(__builtin_ctz(unsigned(mask))));
  }
#endif
  for (; i < end; ++i)
    if (const uint32_t bits = slots[i].cost_bits(); bits >= lo && bits <= hi) f(i);
}

// One planned collapse: a -> b and, on a seam, its twin a2 -> b2; x is where b (and b2) end up.
struct Plan {
  uint32_t a = kNone, b = kNone, a2 = kNone, b2 = kNone;
  uint32_t slot = kNone;  // the candidate's slot
  bool move = false;
  glm::dvec3 x{0.0};
  double cost = 0.0;
};

// One changed face for vertical_bound.
struct Corners {
  Corners() {}  // members left unset: vertical_bound fills each record in place before reading it
  glm::dvec3 p[3];
  glm::dvec2 y[3], ny[3];  // projected before and after (ny: x for the moving corners; faces that stay)
  double h[3], r[3];
  double area, new_area;  // twice the projected areas, before and after
  uint8_t moving;         // bit k: corner k is at a or b (StarFace::at_a | at_b)
  int last_moving;  // the last moving corner (every face has one: it holds a or b); a face that stays has one
  bool dies;
};
// kLanes doubles (quadric.hpp), and what comparisons of them give: -1 where true, per lane.
template <int kLanes>
struct SpokeLanes;
template <>
struct SpokeLanes<2> {
  using Doubles = Lanes;
  using Mask = int64_t __attribute__((vector_size(16)));
};
template <>
struct SpokeLanes<4> {
  using Doubles = WideLanes;
  using Mask = int64_t __attribute__((vector_size(32)));
};
// vertical_bound's division-free crossing tests for spokes [k0, k1) against one old edge (direction (dx, dy),
// origin relative to x (rx, ry), both with the sign that makes sn positive): bit k - k0 set where den =
// x dy - y dx > threshold and 0 < tn = rx y - ry x < den, with (x, y) = (spoke_x[k], spoke_y[k]). kLanes
// spokes per step in vector lanes without branches (about 40 % of pairs pass the first test, at random: as
// branches they were mostly mispredictions; one lane per step cost three times the instructions), each
// lane's outcome kept as its spoke's bit in the lanes (bit k - k0 of lane (k - k0) % kLanes; moving the bits
// to a scalar every step took 12 of its 36 instructions). The lanes compute what the scalar expressions
// would, bit for bit. 4 lanes (one register) in vertical_bound's AVX2 version, 2 in the baseline's (GCC
// lowers 4 lanes without AVX into scalar code: +1.3 G instructions on elephant_1m 0.1; in the AVX2 version
// 2 lanes took 151 M more than 4; the whole command 16,134 -> 16,005 M with this
// function, and 17,269 M for the baseline version alone, against 17,380 M before any AVX2). Reads spoke_x,
// spoke_y up to the next multiple of kLanes above k1 - 1.
template <int kLanes>
[[gnu::always_inline]] inline uint64_t passing_spokes(const double* spoke_x, const double* spoke_y, size_t k0,
                                                      size_t k1, double dx, double dy, double rx, double ry,
                                                      double threshold) {
  using Doubles = typename SpokeLanes<kLanes>::Doubles;
  using Mask = typename SpokeLanes<kLanes>::Mask;
  Mask passed{}, bit;  // bit: lane l's spoke in this step
  if constexpr (kLanes == 4)
    bit = Mask{1, 2, 4, 8};
  else
    bit = Mask{1, 2};
  for (size_t k = k0; k < k1; k += kLanes, bit <<= kLanes) {
    Doubles x, y;
    std::memcpy(&x, &spoke_x[k], sizeof x), std::memcpy(&y, &spoke_y[k], sizeof y);
    const Doubles den = x * dy - y * dx, tn = rx * y - ry * x;
    // Each test selects the spokes' bits (as `cmp ? bit : 0`, GCC 12 keeps the masks in the vector
    // registers; `(cmp) & (cmp) & bit` moved each lane out and back).
    passed |= (den > threshold ? bit : 0) & (tn > 0 ? bit : 0) & (tn < den ? bit : 0);
  }
  if constexpr (kLanes == 4)
    return uint64_t(passed[0] | passed[1] | passed[2] | passed[3]);
  else
    return uint64_t(passed[0] | passed[1]);
}
// Corner k of one of vertical_bound's records: an old edge from corner k to the next, or a spoke's ring
// corner. Read from the record where needed rather than copied out (eight doubles per old edge and spoke:
// elephant_1m 0.1 callgrind, vertical_bound 3,106 -> 3,075 M instructions default, 3,129 -> 3,097 M
// positions-only).
struct CornerRef {
  const Corners* c;
  int k;
};

constexpr uint32_t kAnyRegion = UINT32_MAX;

// A face around a collapsing edge a -> b: bit k of at_a (at_b) is set when its corner k is at a's (b's)
// position. try_collapse's first walk sets them; the normal check and vertical_bound read them.
struct StarFace {
  uint32_t face;
  uint8_t at_a, at_b;
};

// What one thread of the collapse loop needs of its own: the collapse's neighbourhood, vertical_bound's
// faces and edges, and what its collapses changed (merged into the mesh's totals after the loop).
struct Scratch {
  uint32_t region = kAnyRegion;  // collapses must keep every face they read inside this region
  uint32_t region_base = 0;      // region x Simplifier::region_vertices_ (in_region)
  std::vector<uint32_t> na, nb, apex, removed;
  std::vector<StarFace> star_a, star_b;  // the alive faces around a's and b's wedges (for_faces order)
  std::vector<Corners> old;
  std::vector<CornerRef> old_edges, spokes;
  std::vector<double> spoke_x, spoke_y;  // the spokes' directions, for the crossing loop's first test
  size_t removed_triangles = 0;
  double bound = 0.0;  // the largest radius its collapses gave (the mesh's bound when run serially)
  bool error_limited = false;
  bool rejected = false;  // a candidate's slot was set to +inf by a failed collapse
};

enum class Outcome { kCollapsed, kRejected, kOutsideRegion };

// A position's hash for representatives (its top bits pick a bucket, its low 32 bits a slot): equal for
// equal positions (+0 and -0 hash alike).
uint64_t position_hash(const glm::vec3& p) {
  auto bits = [](float f) { return std::bit_cast<uint32_t>(f + 0.0f); };
  const uint64_t h = uint64_t(bits(p.x)) * 0x9E3779B97F4A7C15ull ^
                     uint64_t(bits(p.y)) * 0xC2B2AE3D27D4EB4Full ^
                     uint64_t(bits(p.z)) * 0x165667B19E3779F9ull;
  return h ^ (h >> 29);
}

class Simplifier {
 public:
  Simplifier(const Mesh& in, const Options& o)
      : in_(in), opt_(o), small_(in.triangle_count() <= kSmallTriangles) {}

  Result run() {
    Result result;
    result.input_triangles = in_.triangle_count();
    weld();
    result.weld_remap = weld_remap_;
    build_adjacency();
    classify();
    build_quadrics();
    const size_t target = opt_.target_triangles;
    const size_t start_tris = alive_triangles_;
    bool stalled = false, retried = false;
    uint32_t pass = 0;
    while (alive_triangles_ > target) {
      if (pass++ > 0) {
        compact_faces();
        build_adjacency();
      }
      update_open_edges();
      size_t collapsed = run_pass(target);
      if (opt_.progress && start_tris > target)
        opt_.progress(float(start_tris - alive_triangles_) / float(start_tris - target));
      if (collapsed == 0) {
        // Slots of rejected collapses are +inf until re-evaluated: before giving up, evaluate every edge
        // again once (a neighbour's collapse may have made one of them valid).
        if (!rejected_ || retried) {
          stalled = true;
          break;
        }
        retried = true;
        rejected_ = false;
        slots_.clear();
      } else {
        retried = false;
      }
    }
    // Reached: within 1 % of the triangle target, or stopped by the error bound before it.
    result.target_reached = !stalled || alive_triangles_ <= target + target / 100 || error_limited_;
    output(result);
    return result;
  }

 private:
  const Mesh& in_;
  const Options& opt_;
  // Meshes of at most kSmallTriangles (a DAG group: 512-1024 triangles, simplified while other groups keep
  // the cores busy) run weld's and build_quadrics' loops and gather_candidates' blocks in plain loops
  // (for_each), and goal_cost's select serially with fewer buckets: there, TBB's tasks, per-thread copies
  // and goal_cost's 4096-bucket histograms cost more than the loops. (Loops with a grain of 1024 or more are
  // one task there already.) The results are the same.
  static constexpr size_t kSmallTriangles = 4096;
  const bool small_;

  // f(i) for i in [begin, end): on every core, or in order when small_.
  template <class I, class F>
  void for_each(I begin, I end, F&& f) const {
    if (small_) {
      for (I i = begin; i < end; ++i) f(i);
    } else {
      tbb::parallel_for(begin, end, f);
    }
  }

  // f(range) over blocks of [0, end) of at least `grain` on every core, or over all of it at once when
  // small_ (without a nested TBB call: about 800 instructions each, a few dozen per DAG group).
  template <class F>
  void for_blocks(uint32_t end, uint32_t grain, F&& f) const {
    if (small_)
      f(tbb::blocked_range<uint32_t>(0, end));
    else
      tbb::parallel_for(tbb::blocked_range<uint32_t>(0, end, grain), f);
  }

  // Welded vertices (input vertex -> welded) and their working data (normalized positions).
  std::vector<uint32_t> weld_remap_, source_;  // source_: welded vertex -> first input vertex
  // The UninitializedVector members are first written by parallel loops (weld, renumber_spatially,
  // build_quadrics, run_pass), so that their pages are first touched on every core.
  UninitializedVector<glm::vec3> pos_;
  UninitializedVector<glm::vec3> nrm_;
  UninitializedVector<glm::vec2> uv_;
  UninitializedVector<glm::vec4> col_;
  UninitializedVector<uint32_t> wedge_, pid_;  // wedge ring (same position) and its representative
  std::vector<uint8_t> kind_, touched_, moved_;
  std::vector<float> radius_;  // bound radius r_v (simplify.hpp), normalized units
  UninitializedVector<Quadric> quadric_;
  UninitializedVector<AttributeTerm> attr_;  // channels_ per vertex
  // Weighted attribute channels in the cost: one component of the normal, UV or colour, with its weight.
  struct Channel {
    int attribute;  // 0 normal, 1 uv, 2 colour
    int component;
    float weight;
  };
  std::vector<Channel> channel_;
  int channels_ = 0;
  std::vector<uint32_t> open_out_, open_in_;
  glm::vec3 origin_{0.0f};
  float scale_ = 1.0f;
  double max_error_ = 0.0;
  double prior_error_ = 0.0;    // the largest Options::vertex_error, model units
  bool error_limited_ = false;  // a collapse was refused because of Options::max_error

  UninitializedVector<uint32_t> indices_;  // alive faces; dead ones have indices_[3f] == kNone during a pass
  size_t alive_triangles_ = 0, welded_triangles_ = 0;  // welded_: before the first collapse
  std::vector<uint32_t> offsets_, faces_;              // vertex -> faces (CSR), rebuilt each pass
  UninitializedVector<Slot> slots_;
  // On a small mesh (small_), beside each slot: where its candidate's collapse puts the kept end (Plan::x),
  // as `place` found it with the cost. The candidate's ends are untouched when it is tried (plan_listed), so
  // `place` would find the same again: the try reads it instead (a bake's DAG groups; elephant_1m bake,
  // callgrind: place_with 3,532.7 -> 3,125.2 M instructions, the stores and copies (run_pass,
  // compact_faces) about +110 M). 24 bytes per corner, so a large mesh (elephant_1m 0.1: 205 MB) places
  // again.
  UninitializedVector<glm::dvec3> placed_;
  // Uninitialized: the first pass's resizes (elephant_1m 0.1: 894,508 candidates, 7 MB each) were a serial
  // zero fill and the arrays' first touch, 16-25 ms of CPU each with the other core idle (temporary timers,
  // load 6); now their pages are first touched by the parallel writes of gather_candidates and
  // counting_sort. Every element is written before it is read.
  UninitializedVector<Ranked> order_, sorted_;
  std::vector<float> bucket_;         // goal_cost's candidate costs in one histogram bucket
  std::vector<uint32_t> histograms_;  // goal_cost's, one per block of slots
  std::vector<uint64_t> sort_keys_;   // sort_by_cost's keys
  // Regions of the collapse loop's parallel part (region_of): runs of region_vertices_ vertex numbers in
  // Morton order (about kRegionVertices alive vertices, at least kMinRegions regions on a smaller mesh; the
  // run grows as the mesh shrinks), shifted by region_shift_, which turns each pass so that no band of the
  // mesh is always left to the serial part.
  // region_start_: where each region's candidates begin in sorted_ (grouped by region after the cost sort, as
  // (cost, order_ index); then the serial part's list); pending_: per order_ entry, whether the serial part
  // is to try it.
  static constexpr uint32_t kRegionVertices = 16384, kMinRegions = 2;
  uint32_t region_vertices_ = kRegionVertices, region_shift_ = 0;
  std::vector<uint32_t> region_start_;
  std::vector<uint8_t> pending_;
  Scratch serial_;
  // collapse_in_parts: per vertex, whether its part's walk defers candidates that read it; per part, its
  // thread's scratch and the candidates it deferred.
  std::vector<uint8_t> blocked_;
  struct Part {
    Scratch scratch;
    std::vector<Ranked> deferred;
  };
  std::vector<Part> parts_;
  bool rejected_ = false;  // slots were set to +inf by failed collapses since the last full evaluation
  uint32_t step_ = 0;
  std::vector<Collapse>* record_ = nullptr;

  // ---- set-up ------------------------------------------------------------------------------------------

  // Welds exact duplicates (same position and attributes) and links vertices that share a position into
  // wedge rings, numbered as one loop over the input would: a welded vertex per first input vertex of its
  // position and attributes, in input order; each ring from the position's first wedge to its last, then
  // back in input order (the first one's successor is the newest). Each input vertex's first vertex at its
  // position, then its first with the same position and attributes, by hash (core/representatives.hpp, on
  // every core, instead of a sort by position hash), then one pass in input order links the rings. O(V)
  // expected.
  void weld() {
    const size_t n = in_.vertex_count();
    Bounds box = in_.bounds();
    origin_ = box.empty() ? glm::vec3(0.0f) : box.min;
    float extent = box.empty() ? 0.0f : std::max({box.extent().x, box.extent().y, box.extent().z});
    scale_ = extent > 0 ? extent : 1.0f;
    max_error_ = (opt_.max_error * (1 - 1e-6) - 1e-6 * double(scale_)) / (double(scale_) * (1 + 1e-5));

    const bool hn = in_.has_normals(), hu = in_.has_uvs(), hc = in_.has_colors();
    auto same_attributes = [&](uint32_t i, uint32_t j) {
      return (!hn || in_.normals[i] == in_.normals[j]) && (!hu || in_.uvs[i] == in_.uvs[j]) &&
             (!hc || in_.colors[i] == in_.colors[j]);
    };
    // Positions compare with == (NaN never equal, -0 = +0, as in a hash-table weld); a vertex's class of
    // position and attributes lies within its position's, so the second step hashes the first's result.
    UninitializedVector<uint64_t> hash(n);
    for_each(size_t(0), n, [&](size_t v) { hash[v] = position_hash(in_.positions[v]); });
    const std::vector<uint32_t> first_at = representatives(
        n, [&](size_t v) { return hash[v]; },
        [&](uint32_t a, uint32_t b) { return in_.positions[a] == in_.positions[b]; });
    const std::vector<uint32_t> source =
        !hn && !hu && !hc ? first_at
                          : representatives(
                                n, [&](size_t v) { return hash[first_at[v]]; },
                                [&](uint32_t a, uint32_t b) {
                                  return first_at[a] == first_at[b] && same_attributes(a, b);
                                });
    weld_remap_.assign(n, kNone);
    source_.clear();
    for (uint32_t v = 0; v < n; ++v)
      if (source[v] == v) weld_remap_[v] = uint32_t(source_.size()), source_.push_back(v);
    for (uint32_t v = 0; v < n; ++v) weld_remap_[v] = weld_remap_[source[v]];
    const size_t m = source_.size();
    pos_.resize(m), wedge_.resize(m), pid_.resize(m);
    if (in_.has_normals()) nrm_.resize(m);
    if (in_.has_uvs()) uv_.resize(m);
    if (in_.has_colors()) col_.resize(m);
    for_each(size_t(0), m, [&](size_t k) {
      const uint32_t v = source_[k];
      pos_[k] = (in_.positions[v] - origin_) / scale_;
      if (hn) nrm_[k] = in_.normals[v];
      if (hu) uv_[k] = in_.uvs[v];
      if (hc) col_[k] = in_.colors[v];
      pid_[k] = weld_remap_[first_at[v]];
    });
    // Rings, in input order: a position's first wedge links to the newest wedge so far; each later one
    // links to the one before it (the first's link until then) and becomes the first's link.
    for (size_t k = 0; k < m; ++k) {
      const uint32_t first = pid_[k];
      wedge_[k] = first == k ? uint32_t(k) : std::exchange(wedge_[first], uint32_t(k));
    }
    renumber_spatially();
    kind_.assign(m, kManifold);
    touched_.assign(m, 1);  // every cost is evaluated in the first pass
    moved_.assign(m, 0);
    radius_.assign(m, 0.0f);
    for (uint32_t v = 0; v < n; ++v)
      if (v < opt_.locked.size() && opt_.locked[v]) kind_[weld_remap_[v]] = kLocked;
    // Radii carried from a finer surface (Options::vertex_error), normalized and rounded up; welded copies
    // keep the larger.
    for (uint32_t v = 0; v < n && v < opt_.vertex_error.size(); ++v) {
      const double e = double(opt_.vertex_error[v]);
      prior_error_ = std::max(prior_error_, e);
      float& r = radius_[weld_remap_[v]];
      r = std::max(r, std::nextafter(float(e / double(scale_) * (1 + 1e-6)), INFINITY));
    }

    // The faces on welded vertices, in place on every core (uninitialized: first touched there); one with a
    // vertex out of range or repeated is marked dead, and sort_faces leaves it out. Was a serial loop that
    // cut the dead ones (about 28 instructions per face) after a serial zero fill.
    const size_t input_faces = in_.indices.size() / 3;
    indices_.resize(3 * input_faces);
    for_each(size_t(0), input_faces, [&](size_t t) {
      uint32_t a = in_.indices[3 * t], b = in_.indices[3 * t + 1], c = in_.indices[3 * t + 2];
      if (a < n && b < n && c < n) a = weld_remap_[a], b = weld_remap_[b], c = weld_remap_[c];
      const bool dead = a >= n || b >= n || c >= n || a == b || b == c || a == c;
      indices_[3 * t] = dead ? kNone : a, indices_[3 * t + 1] = b, indices_[3 * t + 2] = c;
    });
    sort_faces();
    alive_triangles_ = welded_triangles_ = indices_.size() / 3;
  }

  // Orders the faces by their smallest vertex, stably (vertices are in Morton order), so that the faces
  // around a vertex lie in a few cache lines of indices_ and slots_: each collapse walks them in cost order,
  // random in space, and in input order the first read of every face was a cache miss (about a third of
  // try_collapse's samples on elephant_1m). Two stable counting sorts, on every core: by runs of `span`
  // vertices (counting_sort), then each run's faces by their vertex. Up to kMaxRuns runs, about kRunFaces
  // faces each: a DAG group of 800 faces in 4096 runs spent most of its sort on empty runs (77 M of the
  // bake's 1.6 G simplifier instructions on refined_elephant). The order does not depend on the runs. Dead
  // faces (weld's) are left out. O(T + V).
  void sort_faces() {
    constexpr size_t kMaxRuns = 4096, kRunFaces = 64;
    const size_t faces = indices_.size() / 3;
    const uint32_t run_count = uint32_t(std::clamp<size_t>(faces / kRunFaces, 1, kMaxRuns));
    const uint32_t span = uint32_t(source_.size() / run_count + 1);
    auto key = [&](size_t f) {
      return std::min({indices_[3 * f], indices_[3 * f + 1], indices_[3 * f + 2]});
    };
    UninitializedVector<uint32_t> by_run(faces);
    std::vector<uint32_t> run_start;
    counting_sort(
        faces, run_count, [&](size_t f) { return indices_[3 * f] == kNone ? run_count : key(f) / span; },
        [&](size_t f, uint32_t position) { by_run[position] = uint32_t(f); }, &run_start);
    UninitializedVector<uint32_t> sorted(3 * size_t(run_start[run_count]));  // each written once below
    for_blocks(run_count, 64, [&](const auto& runs) {
      std::vector<uint32_t> start(span + 1);
      for (uint32_t r = runs.begin(); r < runs.end(); ++r) {
        const uint32_t first = r * span, begin = run_start[r], end = run_start[r + 1];
        std::fill(start.begin(), start.end(), 0);
        for (uint32_t i = begin; i < end; ++i) ++start[key(by_run[i]) - first + 1];
        start[0] = begin;
        for (uint32_t v = 1; v <= span; ++v) start[v] += start[v - 1];
        for (uint32_t i = begin; i < end; ++i) {
          const uint32_t f = by_run[i];
          std::copy_n(&indices_[3 * size_t(f)], 3, &sorted[3 * size_t(start[key(f) - first]++)]);
        }
      }
    });
    indices_.swap(sorted);
  }

  // Renumbers the welded vertices in Morton (Z-curve) order of their positions, so that a collapse's
  // neighbourhood lies in a few cache lines of every per-vertex array: the collapses come in cost order,
  // which is random in space, and on a large mesh in input order most of their time went to cache misses
  // (with the quadrics' origins at the current positions: elephant_1m 10 %, CPU s under load 4-6, default
  // weights 7.5-7.8 -> 6.1-7.6, positions only 5.9-7.0 -> 5.4-6.7; the same collapses up to ties). The faces
  // follow (sort_faces). O(V log V), on every core.
  void renumber_spatially() {
    const size_t m = source_.size();
    UninitializedVector<std::pair<uint64_t, uint32_t>> code(m);
    for_each(uint32_t(0), uint32_t(m), [&](uint32_t v) {
      const glm::vec3 q = glm::clamp(pos_[v], 0.0f, 1.0f) * 2097151.0f;  // pos_ is in [0, 1]^3
      code[v] = {morton_code21(uint32_t(q.x), uint32_t(q.y), uint32_t(q.z)), v};
    });
    // Ties (wedges share a position) by old number. One std::sort on a small mesh: tbb::parallel_sort's
    // tasks cost more than the sort there (the pairs are distinct, so both give the same order).
    if (small_)
      std::sort(code.begin(), code.end());
    else
      tbb::parallel_sort(code.begin(), code.end());
    UninitializedVector<uint32_t> renumbered(m);
    for_each(uint32_t(0), uint32_t(m), [&](uint32_t i) { renumbered[code[i].second] = i; });
    auto permute = [&](auto& values) {
      if (values.size() != m) return;
      std::decay_t<decltype(values)> moved(m);
      for_each(uint32_t(0), uint32_t(m), [&](uint32_t i) { moved[i] = values[code[i].second]; });
      values.swap(moved);
    };
    permute(source_), permute(pos_), permute(nrm_), permute(uv_), permute(col_), permute(wedge_),
        permute(pid_);
    auto rename = [&](auto& vertices) {
      for_each(size_t(0), vertices.size(), [&](size_t i) { vertices[i] = renumbered[vertices[i]]; });
    };
    rename(wedge_), rename(pid_), rename(weld_remap_);
  }

  // Drops dead faces; their corners' cached candidates (and placements) move with them, in one loop without
  // a test per array (a loop per array: elephant_1m bake +130 M instructions, callgrind).
  void compact_faces() {
    auto keep_alive = [&](auto&... values) {  // arrays per corner (indices_ last): the alive faces' entries
      size_t w = 0;
      for (size_t f = 0; f < indices_.size(); f += 3)
        if (indices_[f] != kNone) {
          ((values[w] = values[f], values[w + 1] = values[f + 1], values[w + 2] = values[f + 2]), ...);
          w += 3;
        }
      (values.resize(w), ...);
    };
    if (slots_.size() != indices_.size())
      keep_alive(indices_);
    else if (small_)
      keep_alive(placed_, slots_, indices_);
    else
      keep_alive(slots_, indices_);
  }

  // Vertex -> faces (offsets_, faces_), each vertex's faces in increasing order, as one loop over the
  // corners would list them. On every core: the corners are grouped by runs of 2^kAdjacencyRunBits vertices
  // (counting_sort, stable, their ids parked in faces_), then each run lists its vertices' faces from its
  // own corners. A mesh of one run skips the grouping. O(T + V).
  static constexpr uint32_t kAdjacencyRunBits = 13;
  void build_adjacency() {
    const size_t m = source_.size(), corners = indices_.size();
    const uint32_t runs = uint32_t((m >> kAdjacencyRunBits) + 1);
    offsets_.resize(m + 1);
    faces_.resize(corners);
    std::vector<uint32_t> run_start{0, uint32_t(corners)};
    if (runs > 1)
      counting_sort(
          corners, runs, [&](size_t c) { return indices_[c] >> kAdjacencyRunBits; },
          [&](size_t c, uint32_t position) { faces_[position] = uint32_t(c); }, &run_start);
    for_each(uint32_t(0), runs, [&](uint32_t r) {
      const uint32_t lo = r << kAdjacencyRunBits;
      const uint32_t hi = uint32_t(std::min<size_t>(m, size_t(r + 1) << kAdjacencyRunBits));
      // The run's corners: parked in faces_ (copied out before faces_ is written), or all of them.
      std::vector<uint32_t> parked;
      if (runs > 1) parked.assign(faces_.begin() + run_start[r], faces_.begin() + run_start[r + 1]);
      auto for_corners = [&](auto&& f) {
        if (runs > 1)
          for (uint32_t c : parked) f(c);
        else
          for (uint32_t c = 0; c < corners; ++c) f(c);
      };
      std::vector<uint32_t> next(hi - lo, 0);  // degrees, then where each vertex's next face goes
      for_corners([&](uint32_t c) { ++next[indices_[c] - lo]; });
      for (uint32_t v = lo, at = run_start[r]; v < hi; ++v) {
        offsets_[v] = at;
        at += std::exchange(next[v - lo], at);
      }
      for_corners([&](uint32_t c) { faces_[next[indices_[c] - lo]++] = c / 3; });
    });
    offsets_[m] = uint32_t(corners);
  }

  // f(out, in) for each alive face (v, out, in) of v (counter-clockwise order), in face order.
  template <class F>
  void for_fan(uint32_t v, F&& f) const {
    for (uint32_t s = offsets_[v]; s < offsets_[v + 1]; ++s) {
      const uint32_t* t = &indices_[3 * size_t(faces_[s])];
      if (t[0] == kNone) continue;
      int k = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
      f(t[(k + 1) % 3], t[(k + 2) % 3]);
    }
  }

  // Out- and in-neighbours of v over its alive faces (for_fan).
  void fan(uint32_t v, std::vector<uint32_t>& outs, std::vector<uint32_t>& ins) const {
    outs.clear(), ins.clear();
    for_fan(v, [&](uint32_t out, uint32_t in) { outs.push_back(out), ins.push_back(in); });
  }

  // Whether a face holds the directed edge j -> i, i.e. edge i -> j has a twin: one walk over i's faces
  // (all alive after compact_faces), O(degree).
  bool has_edge(uint32_t j, uint32_t i) const {
    for (uint32_t s = offsets_[i]; s < offsets_[i + 1]; ++s) {
      const uint32_t* t = &indices_[3 * size_t(faces_[s])];
      if (t[0] == i ? t[2] == j : (t[1] == i ? t[0] == j : t[1] == j)) return true;
    }
    return false;
  }

  // Vertex kinds (simplify.hpp): open edges, non-manifold edges (a directed edge twice) and fans (a vertex
  // whose faces do not form one disc or one open fan), then wedge rings.
  void classify() {
    const size_t m = source_.size();
    open_out_.assign(m, kNone), open_in_.assign(m, kNone);
    std::vector<uint8_t> open_count(m, 0), complex(m, 0);
    for_blocks(uint32_t(m), 4096, [&](const auto& r) {
      for (uint32_t v = r.begin(); v < r.end(); ++v) classify_fan(v, open_count, complex);
    });
    // Each vertex's kind from its own (user-locked) kind and the fans' results: on every core (one core took
    // 11.4 M instructions on elephant_1m).
    for_blocks(uint32_t(m), 4096, [&](const auto& r) {
      for (uint32_t v = r.begin(); v < r.end(); ++v) {
        if (kind_[v] == kLocked || complex[v]) {
          kind_[v] = kLocked;
          continue;
        }
        uint32_t w = wedge_[v];
        if (w == v) {
          kind_[v] = open_count[v] == 0 ? kManifold : kBorder;
        } else if (wedge_[w] == v && open_count[v] == 1 && open_count[w] == 1 && !complex[w] &&
                   pid_[open_out_[v]] == pid_[open_in_[w]] && pid_[open_in_[v]] == pid_[open_out_[w]]) {
          kind_[v] = kSeam;
        } else {
          kind_[v] = kLocked;
        }
      }
    });
    // A seam vertex whose partner was locked by the user is locked too (serially, in order: a vertex locked
    // here also locks a later partner).
    for (uint32_t v = 0; v < m; ++v)
      if (kind_[v] == kSeam && kind_[wedge_[v]] != kSeam) kind_[v] = kLocked;
  }

  // classify's first step for one vertex: its open edges (open_out_, open_in_, open_count) and whether its
  // fan is complex (a directed edge twice, more than one open edge, or faces not forming one disc or fan).
  // A complex vertex is locked, so its open edges are not needed: a repeated edge ends the scan. Writes
  // only v's entries, so vertices run in parallel. Its faces are all alive (classify runs before the first
  // collapse), so its degree is its count of faces and its fan goes into arrays on the stack. O(degree^2)
  // compares: the repeats, then one scan of all (in, out) pairs, which also links the faces for the walk.
  void classify_fan(uint32_t v, std::vector<uint8_t>& open_count, std::vector<uint8_t>& complex) {
    if (offsets_[v + 1] - offsets_[v] > 256) {
      complex[v] = 1;
      return;
    }
    // next[i]: the face g with g.out == face i's in (one at most once out-neighbours do not repeat; kNoFace
    // when face i's in edge is open); out_closed[i]: whether face i's out edge has a twin. Set below, cleared
    // here with the fan (set in a loop of their own, they were two calls of memset per vertex).
    constexpr uint16_t kNoFace = UINT16_MAX;
    std::array<uint32_t, 256> outs, ins;
    std::array<uint16_t, 256> next;
    std::array<uint8_t, 256> out_closed;
    size_t deg = 0;
    for_fan(v, [&](uint32_t out, uint32_t in) {
      outs[deg] = out, ins[deg] = in, next[deg] = kNoFace, out_closed[deg] = 0;
      ++deg;
    });
    if (deg == 0) return;
    for (size_t i = 0; i < deg; ++i)
      for (size_t j = i + 1; j < deg; ++j)
        if (outs[j] == outs[i]) {
          complex[v] = 1;
          return;
        }

    // One scan of all (in, out) pairs: next and out_closed.
    for (size_t i = 0; i < deg; ++i)
      for (size_t j = 0; j < deg; ++j)
        if (outs[j] == ins[i]) {
          next[i] = uint16_t(j), out_closed[j] = 1;
          break;
        }
    uint32_t n_open_out = 0, n_open_in = 0, start = 0;
    for (size_t i = 0; i < deg; ++i) {
      if (!out_closed[i]) ++n_open_out, open_out_[v] = outs[i], start = uint32_t(i);
      if (next[i] == kNoFace) ++n_open_in, open_in_[v] = ins[i];
    }
    if (n_open_out > 1 || n_open_in > 1 || n_open_out != n_open_in) complex[v] = 1;
    open_count[v] = uint8_t(std::min<uint32_t>(n_open_out, 2));
    if (complex[v]) return;
    // Walk the fan from the face after the open edge (or any face) along next.
    size_t visited = 1, cur = start;
    while (visited < deg && next[cur] != kNoFace && next[cur] != start) cur = next[cur], ++visited;
    if (visited != deg) complex[v] = 1;
  }

  // Border and seam vertices: their single open edge out and in, this pass (kNone when not single).
  void update_open_edges() {
    const size_t m = source_.size();
    for_blocks(uint32_t(m), 4096, [&](const auto& r) {
      thread_local std::vector<uint32_t> outs, ins;
      for (uint32_t v = r.begin(); v < r.end(); ++v) {
        open_out_[v] = open_in_[v] = kNone;
        if (kind_[v] != kBorder && kind_[v] != kSeam) continue;
        fan(v, outs, ins);
        uint32_t no = 0, ni = 0;
        for (size_t i = 0; i < outs.size(); ++i) {
          if (std::find(ins.begin(), ins.end(), outs[i]) == ins.end()) ++no, open_out_[v] = outs[i];
          if (std::find(outs.begin(), outs.end(), ins[i]) == outs.end()) ++ni, open_in_[v] = ins[i];
        }
        if (no != 1 || ni != 1) open_out_[v] = open_in_[v] = kNone;
      }
    });
  }

  // Adds face f's plane quadric and attribute gradients to its corners in [lo, hi) (build_quadrics);
  // `weighted`: channels_ weighted values per vertex (s_j = weight_j x component_j); gradient: room for
  // channels_ gradients. kChannels: channels_ when known at compile time (the loops over the channels
  // unrolled: positions only, or normals only), else -1. Flattened: GCC 12 left Quadric::add_shifted a call
  // here, with the face's quadric spilled for it (inlined, a refined_elephant bake's add_face calls take
  // 170.3 -> 156.3 M instructions; the same operations, so the same bits).
  template <int kChannels>
  [[gnu::flatten]] LODSTREAM_HOT_PATH void add_face(uint32_t f, uint32_t lo, uint32_t hi,
                                                    const float* weighted, AttributeTerm* gradient) {
    const int channels = kChannels >= 0 ? kChannels : channels_;
    const uint32_t v0 = indices_[3 * size_t(f)], v1 = indices_[3 * size_t(f) + 1],
                   v2 = indices_[3 * size_t(f) + 2];
    auto mine = [&](uint32_t v) { return v >= lo && v < hi; };
    if (!mine(v0) && !mine(v1) && !mine(v2)) return;
    const glm::vec3 p0 = pos_[v0], e1 = pos_[v1] - p0, e2 = pos_[v2] - p0;
    const glm::vec3 n = glm::cross(e1, e2);
    const float len = glm::length(n);
    if (!(len > 0)) return;
    const float area = 0.5f * len;
    Quadric face;  // relative to p0
    face.add_plane(n / len, 0.0f, area);
    face.w = area;
    if (channels > 0) {
      const float *s0 = weighted + v0 * size_t(channels), *s1 = weighted + v1 * size_t(channels),
                  *s2 = weighted + v2 * size_t(channels);
      // s(p) = g.(p - p0) + s0 with g = (s1 - s0) ge1 + (s2 - s0) ge2 (the face's gradient).
      const glm::vec3 ge1 = glm::cross(e2, n) / (len * len), ge2 = glm::cross(n, e1) / (len * len);
      for (int j = 0; j < channels; ++j) {
        gradient[j] = {(s1[j] - s0[j]) * ge1 + (s2[j] - s0[j]) * ge2, s0[j]};
        FloatLanes nd;  // (g, d)
        std::memcpy(&nd, &gradient[j], sizeof nd);
        face.add_plane(nd, area);
      }
    }
    // The face's terms in memory for the shifts' 8-byte loads (widen): held in registers, GCC 12 builds
    // them with vmovq xmm, xmm, which valgrind 3.19 cannot decode.
    asm("" : "+m"(face));
    for (int k = 0; k < 3; ++k) {  // relative to each corner's own origin (origin_of)
      const uint32_t v = k == 0 ? v0 : (k == 1 ? v1 : v2);
      if (!mine(v)) continue;
      const glm::vec3 d = k == 0 ? glm::vec3(0.0f) : (k == 1 ? e1 : e2);  // pos_[v] - p0
      if (k == 0)
        quadric_[v].add(face);  // the shift by 0
      else
        quadric_[v].add_shifted(face, glm::dvec3(d));
      // (G, D) += area (g, d + g.d) for each channel, the four floats in vector lanes (the same operations
      // per lane as the scalar expressions, so the same bits).
      for (int j = 0; j < channels; ++j) {
        FloatLanes sum, term;
        char* t = reinterpret_cast<char*>(&attr_[v * size_t(channels) + j]);
        std::memcpy(&sum, t, sizeof sum), std::memcpy(&term, &gradient[j], sizeof term);
        term[3] += glm::dot(gradient[j].g, d);
        sum += area * term;
        std::memcpy(t, &sum, sizeof sum);
      }
    }
  }

  // Face plane quadrics (area-weighted), attribute gradients (Hoppe 99) and boundary/seam penalty planes.
  // Each face's planes (position and every channel) are summed once, relative to its first corner, then
  // shifted to each corner's origin (Quadric::add_shifted): one shift per corner instead of 1 + channels
  // planes per corner. O(T (channels + 1)), on both cores.
  void build_quadrics() {
    const size_t m = source_.size();
    choose_channels();
    quadric_.clear(), attr_.clear();
    quadric_.resize(m), attr_.resize(m * size_t(channels_));  // zeroed per chunk below
    // Vertex ranges, one per chunk of faces (faces are sorted by their smallest vertex, sort_faces): a
    // chunk's faces add to their corners in its range; a face with a corner in a later range is also listed
    // for that range, which adds it before its own faces. Every vertex then sums its faces in face order, as
    // one loop over the faces would, and the chunks run in parallel.
    // One chunk for a small mesh: its vertex ranges would be a few dozen vertices, so that most faces
    // straddle and each computes its planes once per range it touches.
    const uint32_t chunks = small_ ? 1 : 16;
    std::vector<uint32_t> first_vertex(chunks + 1), first_face(chunks + 1);
    auto key = [&](size_t f) {
      return std::min({indices_[3 * f], indices_[3 * f + 1], indices_[3 * f + 2]});
    };
    const size_t faces = indices_.size() / 3;
    for (uint32_t k = 0; k <= chunks; ++k) {
      first_vertex[k] = uint32_t(uint64_t(m) * k / chunks);
      size_t lo = 0, hi = faces;  // the first face whose key is >= first_vertex[k]
      while (lo < hi) {
        const size_t mid = (lo + hi) / 2;
        if (key(mid) < first_vertex[k])
          lo = mid + 1;
        else
          hi = mid;
      }
      first_face[k] = uint32_t(lo);
    }
    std::vector<std::vector<uint32_t>> straddling(chunks);  // faces with a corner in a later range
    for_each(uint32_t(0), chunks, [&](uint32_t k) {
      for (uint32_t f = first_face[k]; f < first_face[k + 1]; ++f)
        if (std::max({indices_[3 * f], indices_[3 * f + 1], indices_[3 * f + 2]}) >= first_vertex[k + 1])
          straddling[k].push_back(f);
    });
    // The weighted channel values, once per vertex (add_face reads them once per corner).
    UninitializedVector<float> weighted(m * size_t(channels_));
    for_each(size_t(0), m, [&](size_t v) {
      for (int j = 0; j < channels_; ++j)
        weighted[v * channels_ + j] = channel(uint32_t(v), j) * channel_[j].weight;
    });
    auto add_chunk = [&]<int kChannels>(uint32_t k) {
      std::vector<AttributeTerm> gradient(channels_);
      const uint32_t lo = first_vertex[k], hi = first_vertex[k + 1];
      std::fill(quadric_.data() + lo, quadric_.data() + hi, Quadric{});
      std::fill(attr_.data() + lo * size_t(channels_), attr_.data() + hi * size_t(channels_),
                AttributeTerm{});
      for (uint32_t earlier = 0; earlier < k; ++earlier)
        for (uint32_t f : straddling[earlier])
          add_face<kChannels>(f, lo, hi, weighted.data(), gradient.data());
      for (uint32_t f = first_face[k]; f < first_face[k + 1]; ++f)
        add_face<kChannels>(f, lo, hi, weighted.data(), gradient.data());
    };
    for_each(uint32_t(0), chunks, [&](uint32_t k) {
      if (channels_ == 0)
        add_chunk.template operator()<0>(k);
      else if (channels_ == 3)
        add_chunk.template operator()<3>(k);
      else
        add_chunk.template operator()<-1>(k);
    });
    // Penalty planes through open edges (borders and both sides of seams), perpendicular to their face.
    // Manifold vertices have none.
    std::vector<uint32_t> outs, ins;
    for (uint32_t v = 0; v < m; ++v) {
      if (kind_[v] == kManifold) continue;
      fan(v, outs, ins);
      for (size_t i = 0; i < outs.size(); ++i) {
        if (std::find(ins.begin(), ins.end(), outs[i]) != ins.end()) continue;
        glm::vec3 pa = pos_[v], pb = pos_[outs[i]], pc = pos_[ins[i]];
        glm::vec3 e = pb - pa, n = glm::cross(e, pc - pa);
        glm::vec3 pn = glm::cross(e, n);
        float l = glm::length(pn);
        if (!(l > 0)) continue;
        pn /= l;
        const float weight = opt_.boundary_weight * glm::dot(e, e);
        quadric_[v].add_plane(pn, 0.0f, weight);
        quadric_[outs[i]].add_plane(pn, -glm::dot(pn, pa - pb), weight);
      }
    }
  }

  // The weighted channels, less those constant over the whole mesh: their gradients are 0 and their
  // quadrics (W s^2 - (W s)^2 / W) only float noise, which took 12.7 % of the instructions on horse (its
  // alpha) and whose rounding decided collapse order.
  void choose_channels() {
    const size_t m = source_.size();
    auto add = [&](int attribute, const float* first, size_t stride, int components, float weight) {
      if (weight <= 0 || m == 0) return;
      for (int i = 0; i < components; ++i) {
        bool constant = true;
        for (size_t v = 1; v < m && constant; ++v) constant = first[v * stride + i] == first[i];
        if (!constant) channel_.push_back({attribute, i, weight});
      }
    };
    if (nrm_.size() == m) add(0, &nrm_[0].x, 3, 3, opt_.normal_weight);
    if (uv_.size() == m) add(1, &uv_[0].x, 2, 2, opt_.uv_weight);
    if (col_.size() == m) add(2, &col_[0].x, 4, 4, opt_.color_weight);
    channels_ = int(channel_.size());
  }

  // Component j of v's attributes (unweighted).
  float& channel(uint32_t v, int j) {
    const Channel& c = channel_[j];
    return c.attribute == 0 ? nrm_[v][c.component]
                            : (c.attribute == 1 ? uv_[v][c.component] : col_[v][c.component]);
  }

  // The origin of v's quadric and attribute terms: its current position, the same for all its wedges (a
  // collapse that moves b re-bases b's wedges onto x, rebase). Quadrics relative to a nearby origin keep
  // their float terms small: relative to the model's corner, A, b and c are about W and cancel to W dist^2,
  // which float rounding (1e-7 W) drowned at the fine levels (distances up to 3e-4 of the extent, the
  // Hausdorff distances being compared). The position itself, not the input position, so that no collapse
  // reads the input mesh (in input order, a cache miss per read: 60 % of `place` on elephant_1m).
  glm::dvec3 origin_of(uint32_t v) const { return glm::dvec3(pos_[v]); }

  // Moves v's quadric and attribute terms to an origin `d` further (Reduced::add: Q(y' + d); an attribute
  // g.y + d_s becomes g.y' + d_s + g.d).
  void rebase(uint32_t v, const glm::dvec3& d) {
    Quadric moved;
    moved.add_shifted(quadric_[v], d);
    quadric_[v] = moved;
    for (int j = 0; j < channels_; ++j) {
      AttributeTerm& t = attr_[v * size_t(channels_) + j];
      t.d += float(glm::dot(glm::dvec3(t.g), d));
    }
  }

  // ---- planning ----------------------------------------------------------------------------------------

  // Kind rules: may a be removed into b? Finds the seam twin a2 -> b2.
  bool can_remove(uint32_t a, uint32_t b, Plan& p) const {
    p.a = a, p.b = b, p.a2 = p.b2 = kNone;
    switch (kind_[a]) {
      case kManifold:
        return true;
      case kBorder:
        return b == open_out_[a] || b == open_in_[a];
      case kSeam: {
        if (b != open_out_[a] && b != open_in_[a]) return false;
        uint32_t a2 = wedge_[a];
        for (uint32_t c : {open_out_[a2], open_in_[a2]})
          if (c != kNone && c != b && pid_[c] == pid_[b]) p.a2 = a2, p.b2 = c;
        return p.b2 != kNone;
      }
      default:
        return false;
    }
  }

  // Placement and cost of a planned collapse: the summed quadric Q = Q_a + Q_b of both positions (all
  // wedges), attribute channels eliminated per merged wedge pair; optimal x when both ends may move, else
  // x = b. The cost is Q(x) / W, the area-weighted mean squared distance to both ends' planes (and
  // attribute error). Positions only, it is never below kEndShare times either end's own:
  //   cost = max(Q(x) / W, k Q_a(x) / W_a, k Q_b(x) / W_b),  k = kEndShare.
  // The sum alone dilutes a small end's error into a large end's area (a ridge vertex merged into one that
  // already stands for a wide smooth region is nearly free). meshoptimizer ranks by the removed end's own
  // quadric, Q_a(b) / W_a, which never dilutes; k = 1 raised the mean distance by 16 %, k = 0.1 keeps it.
  // Measured with quadrics relative to each vertex (origin_of) it changes little: elephant_1m 10 %
  // identical, horse 10 % Hausdorff 0.87x -> 0.85x meshoptimizer's, 1 % 0.54x -> 0.52x. With attribute
  // weights (attributes eliminated per end) it measured mixed, so it applies positions only.
  // One version per channel count known at compile time (place_with, as add_face): positions only, or
  // normals alone, else channels_. Not inlined: inlined into its callers it changed how GCC compiled them
  // (try_collapse +104 M instructions on elephant_1m 0.1).
  [[gnu::noinline]] void place(Plan& p) const {
    if (channels_ == 0)
      place_with<0>(p);
    else if (channels_ == 3)
      place_with<3>(p);
    else
      place_with<-1>(p);
  }
  // place for kChannels channels (-1: channels_). Positions only it has no channel code to hold registers
  // for, and with normals alone the channel sums are unrolled (elephant_1m 0.1 callgrind: place 2,925.9 ->
  // 2,698.3 M instructions default, 2,120.2 -> 2,044.2 M positions-only; the dispatch above 37.1 / 26.0 M).
  template <int kChannels>
  LODSTREAM_HOT_PATH void place_with(Plan& p) const {
    constexpr double kEndShare = 0.1;
    const int channels = kChannels >= 0 ? kChannels : channels_;
    // Everything relative to b's origin o (a's quadrics shifted by o - o_a; b's wedges share o), x = o + y.
    const glm::dvec3 o = origin_of(p.b), shift = o - origin_of(p.a);
    // Q_a (side 0) or Q_b (side 1), summed over the end's wedges, and its weight W_side in `w_side`. The
    // end-share rule below sums one again (the same operations, so the same bits) rather than keeping both
    // live through the whole function, where they took registers from the rest and were spilled
    // (elephant_1m 0.1 callgrind: place 3,297.1 -> 3,107.9 M instructions default).
    auto own = [&](int side, double& w_side) __attribute__((always_inline)) {
      Reduced q;
      w_side = 0.0;
      const uint32_t first = side == 0 ? p.a : p.b;
      uint32_t v = first;
      do {
        if (side == 0)
          q.add(quadric_[v], shift);
        else
          q.add(quadric_[v]);
        w_side += quadric_[v].w, v = wedge_[v];
      } while (v != first);
      return q;
    };
    std::array<double, 2> own_w;
    Reduced r = own(0, own_w[0]);
    r.add(own(1, own_w[1]));
    const double w = own_w[0] + own_w[1];
    for (int pair = 0; pair < 2 && channels > 0; ++pair) {
      uint32_t a = pair ? p.a2 : p.a, b = pair ? p.b2 : p.b;
      if (a == kNone) continue;
      double ww = double(quadric_[a].w) + quadric_[b].w;
      if (!(ww > 0)) continue;
      ChannelSums sums;
      const AttributeTerm *ta = &attr_[a * size_t(channels)], *tb = &attr_[b * size_t(channels)];
      for (int j = 0; j < channels; ++j) sums.add(ta[j], tb[j], shift);
      r.eliminate(sums, ww);
    }
    const glm::dvec3 pa = glm::dvec3(pos_[p.a]) - o, pb = glm::dvec3(pos_[p.b]) - o;
    const uint8_t ka = kind_[p.a];
    p.move = moves(p);
    // Q(x), kept from the choice of x where it was evaluated there (the same call on the same point).
    double q_x;
    if (!p.move) {
      p.x = pb;
      q_x = r.eval(pb);
    } else {
      glm::dvec3 x, e = pa - pb, mid = 0.5 * (pa + pb);
      // Border and seam vertices stay on their polyline: x on the edge (the minimum along it).
      // An end is preferred unless the interior point halves the cost (keeps corners exactly).
      if (ka != kManifold) {
        double ca = r.eval(pa), cb = r.eval(pb);
        x = ca < cb ? pa : pb, q_x = ca < cb ? ca : cb;
        glm::dvec3 opt = pb + r.segment_parameter(pb, e) * e;
        if (const double q_opt = r.eval(opt); q_opt < 0.5 * std::min(ca, cb)) x = opt, q_x = q_opt;
      } else if (!r.solve(x) || glm::dot(x - mid, x - mid) > glm::dot(e, e)) {
        // Ill-conditioned (or far away): the best of both ends, the midpoint and the minimum along the edge,
        // their costs from Q(pb) and the edge's line (Reduced::Line) instead of four evaluations: 32 % of
        // the calls positions-only, 15 % default (elephant_1m 0.1 callgrind: place 2,333.5 -> 2,094.2 M
        // instructions positions-only, 3,107.9 -> 2,973.6 M default). Not the same bits as the evaluations
        // (Q(pb) + t (2 g + t den) rounds differently), but the costs are stored as floats: 20 simplify
        // outputs and 4 bakes compared came out identical, elephant_5m 0.1 differs in one vertex (default)
        // and 58 bytes (positions-only), same triangles and Hausdorff.
        const double q_b = r.unclamped(pb);
        const Reduced::Line l = r.line(pb, e);
        const double t_opt = l.parameter();
        x = pb;
        q_x = Reduced::clamped(q_b);
        const std::pair<double, glm::dvec3> cands[3] = {{1.0, pa}, {0.5, mid}, {t_opt, pb + t_opt * e}};
        for (const auto& [t, c] : cands)
          if (const double v = l.at(q_b, t); v < q_x) q_x = v, x = c;
      } else {
        q_x = r.eval(x);
      }
      p.x = x;
    }
    const glm::dvec3 y = p.x;
    p.x += o;
    p.cost = q_x / (w + 1e-20);
    if (channels > 0) return;
    // An end's own term can exceed the sum's only when W_side < k W (Q_side(x) <= Q(x), rounding aside:
    // both are sums of squares), so only the smaller end of an unbalanced edge is evaluated.
    for (int side = 0; side < 2; ++side) {
      double w_side;
      if (own_w[side] > 0 && own_w[side] < kEndShare * w)
        p.cost = std::max(p.cost, kEndShare * own(side, w_side).eval(y) / w_side);
    }
  }

  // Whether a planned collapse moves b to an optimal x (else x = b): both ends of one kind that may move.
  bool moves(const Plan& p) const {
    return !opt_.half_edge && kind_[p.a] == kind_[p.b] && kind_[p.a] != kLocked;
  }

  // The cheaper allowed direction of edge (i, j), as a candidate, and its placement in `x`; cost = +inf
  // when neither is allowed.
  Candidate evaluate(uint32_t i, uint32_t j, glm::dvec3& x) const {
    Candidate best{std::numeric_limits<float>::infinity(), kNone, kNone};
    Plan p;
    if (can_remove(i, j, p)) {
      place(p);
      best = {float(p.cost), i, j}, x = p.x;
      if (p.move) return best;  // symmetric: the other direction is the same collapse
    }
    if (can_remove(j, i, p)) {
      place(p);
      if (float(p.cost) < best.cost) best = {float(p.cost), j, i}, x = p.x;
    }
    return best;
  }

  // ---- one pass --------------------------------------------------------------------------------------

  // Candidates live per face corner (slots_[3f + k]: the edge from corner k to corner k + 1), so that a
  // pass re-evaluates only edges with an end touched by the previous pass: an edge whose ends kept their
  // quadrics, positions and faces keeps its cost and allowed direction (open edges and seam twins only
  // change at touched vertices). The faces are visited in order in parallel blocks, each corner's edge
  // checking its ends' touched_ (O(T / cores) per pass, sequential in indices_ and slots_; listing the
  // neighbours of touched vertices first was a serial O(V) scan per pass, 3 % of the wall time on
  // elephant_1m; visiting each vertex's fan through faces_ searched each face for the vertex's corner:
  // elephant_1m 0.1, this loop's own instructions 471.3 -> 396.8 M, callgrind). An edge with a twin is
  // evaluated once, from its smaller end. Every edge at a manifold vertex has a twin (its fan is a closed
  // disc, and collapses keep it one: the link condition), so only other vertices walk their faces to find out
  // (has_edge: 1 % of the instructions). Every touched edge is evaluated: elephant_1m 0.1 makes 8.3
  // evaluations per collapse (3.3 of them the first pass's, 1 the try's) in 6 passes, and nearly all touched
  // edges fall under the next pass's limit, so evaluating them lazily (only once the limit reaches their old
  // cost) saved 1.9 % of them, took 10 passes and raised the bound 2.8x.
  size_t run_pass(size_t target) {
    const bool all = slots_.size() != indices_.size();
    if (all) slots_.clear(), slots_.resize(indices_.size());  // every slot is written below
    if (all && small_) placed_.clear(), placed_.resize(indices_.size());
    const uint32_t faces = uint32_t(indices_.size() / 3);
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, faces, 2048), [&](const auto& r) {
      for (uint32_t f = r.begin(); f < r.end(); ++f) {
        const uint32_t* t = &indices_[3 * size_t(f)];  // faces are all alive (compact_faces)
        for (uint32_t k = 0; k < 3; ++k) {
          const uint32_t i = t[k], j = t[k == 2 ? 0 : k + 1];
          if (!all && !touched_[i] && !touched_[j]) continue;
          Slot& slot = slots_[3 * size_t(f) + k];
          if (i > j && (kind_[i] == kManifold || has_edge(j, i))) {
            slot = Slot::none();
          } else {
            glm::dvec3 x(0.0);
            const Candidate c = evaluate(i, j, x);
            slot = Slot::make(c.cost, c.a == j);
            if (small_) placed_[3 * size_t(f) + k] = x;
          }
        }
      }
    });
    std::fill(touched_.begin(), touched_.end(), 0);
    // Pass limit (as meshoptimizer does): most collapses remove two triangles; allow costs up to 1.5x the one
    // that would reach the target, so that the pass order stays close to the greedy order. Only candidates
    // under the limit are sorted. When none of them is valid, the pass is run again without the limit (else
    // it would stop short of the target with valid collapses left).
    size_t collapsed = 0;
    for (bool limited : {true, false}) {
      const size_t goal = (alive_triangles_ - target + 1) / 2;
      const float limit = limited ? 1.5f * goal_cost(goal) : std::numeric_limits<float>::infinity();
      gather_candidates(limit);
      sort_by_cost(order_, sorted_, sort_keys_);
      collapsed = collapse_in_order(limit, target);
      if (collapsed > 0 || std::isinf(limit)) break;
    }
    return collapsed;
  }

  // Valid candidates in slots_ are visited in blocks of kSlotBlock slots, in parallel.
  static constexpr size_t kSlotBlock = size_t(1) << 16;

  // The ends of slot s's edge as its face holds them: corner s % 3 and the next one. One remainder by 3 (a
  // multiply): the prefetch chain, plan_listed and group_by_region read this about five times per candidate,
  // and a second remainder for the next corner cost 61 M instructions on elephant_1m 0.1 (whole command
  // 15,567.7 -> 15,506.8 M).
  std::pair<uint32_t, uint32_t> edge(uint32_t s) const {
    const uint32_t k = s % 3;
    return {indices_[s], indices_[k == 2 ? s - 2 : s + 1]};
  }

  // The candidate in slot s, its ends read from the face (Slot); a = kNone when the face is dead.
  Candidate listed(uint32_t s) const {
    const Slot slot = slots_[s];
    if (indices_[s - s % 3] == kNone) return {slot.cost(), kNone, kNone};
    const auto [i, j] = edge(s);
    return slot.reverse() ? Candidate{slot.cost(), j, i} : Candidate{slot.cost(), i, j};
  }

  // The candidates under `limit` into order_, scattered from slot order by i -> i * P mod n (P prime > n, so
  // a permutation): the cost sort keeps this order among equal costs, so that flat regions (all costs equal)
  // collapse spread out rather than row by row in face order, the same way on every run. Blocks of slots
  // count theirs, then write from their prefix sum: O(T / cores).
  void gather_candidates(float limit) {
    constexpr uint64_t kScatter = 2654435761u;  // prime, above any candidate count
    const size_t blocks = (slots_.size() + kSlotBlock - 1) / kSlotBlock;
    std::vector<size_t> start(blocks + 1, 0);
    // A valid cost <= limit (>= 0, not NaN) is one whose bits are <= the limit's and the largest finite's.
    const uint32_t top = std::min(std::bit_cast<uint32_t>(limit), 0x7f7fffffu);
    auto block = [&](size_t b, auto&& f) {
      const size_t i = b * kSlotBlock, e = std::min(slots_.size(), i + kSlotBlock);
      for_slots_in(slots_.data(), i, e, 0, top, [&](size_t k) { f(slots_[k].cost(), k); });
    };
    for_each(size_t(0), blocks, [&](size_t b) { block(b, [&](float, size_t) { ++start[b + 1]; }); });
    for (size_t b = 0; b < blocks; ++b) start[b + 1] += start[b];
    const size_t n = start[blocks];
    order_.resize(n);
    if (n == 0) return;
    // k P mod n stepped by P mod n: one division per block instead of one per candidate.
    const uint64_t step = kScatter % n;
    for_each(size_t(0), blocks, [&](size_t b) {
      uint64_t at = start[b] * kScatter % n;
      block(b, [&](float cost, size_t i) {
        order_[at] = {cost, uint32_t(i)};
        at += step;
        if (at >= n) at -= n;
      });
    });
  }

  // The collapse loop over order_ (cost order, up to `limit`, until the target): independent collapses,
  // none touching a vertex an earlier one in this pass touched. Large passes (not recording collapses) run
  // it first on many small regions at once (both cores, each region's data cache-resident: candidates come in
  // cost order, random in space), each region taking its own candidates in order up to its share of the
  // triangles still to remove (in proportion to its candidates); collapses whose faces cross a region's
  // border, and what a region left, follow serially in order. Each region's outcome depends only on its own
  // faces, so the result is the same on every run. Returns the number of collapses.
  size_t collapse_in_order(float limit, size_t target) {
    size_t collapsed = 0;
    constexpr size_t kParallelMin = 1024;
    const bool parallel = !record_ && order_.size() >= kParallelMin && alive_triangles_ > target + 8;
    if (parallel) {
      group_by_region();
      const size_t n = order_.size(), removable = alive_triangles_ - target;
      const uint32_t regions = uint32_t(region_start_.size() - 1);
      tbb::enumerable_thread_specific<Scratch> scratch;
      std::atomic<size_t> count{0};
      tbb::parallel_for(tbb::blocked_range<uint32_t>(0, regions, 1), [&](const auto& range) {
        Scratch& s = scratch.local();
        size_t here = 0;
        for (uint32_t r = range.begin(); r < range.end(); ++r) {
          const uint32_t begin = region_start_[r], end = region_start_[r + 1];
          const size_t quota = size_t(double(removable) * (end - begin) / double(n));
          const size_t removed_before = s.removed_triangles;
          s.region = r, s.region_base = r * region_vertices_;
          for (uint32_t k = begin; k < end; ++k) {
            if (s.removed_triangles - removed_before + 2 > quota) break;
            prefetch(sorted_.data(), k, end);
            const uint32_t i = sorted_[k].slot;
            pending_[i] = 0;
            Plan p;
            if (!plan_listed(i, p)) continue;
            switch (try_collapse(p, s)) {
              case Outcome::kCollapsed:
                ++here;
                break;
              case Outcome::kOutsideRegion:
                pending_[i] = 1;
                break;
              case Outcome::kRejected:
                break;
            }
          }
        }
        count += here;
      });
      collapsed = count;
      for (Scratch& s : scratch) gather(s);
    }
    // The serial part: every candidate, or what the regions left pending, in cost order, listed in sorted_
    // (the regions are done with it) so that prefetch can look ahead along it (on large meshes: on a small
    // one everything is in cache and the prefetch chain would only cost instructions). Costs ascend, so
    // stopping at the first listed candidate over the limit stops where a scan of all of order_ would.
    uint32_t end = 0;
    sorted_.resize(order_.size());
    for (uint32_t i = 0; i < order_.size(); ++i)
      if (!parallel || pending_[i]) sorted_[end++] = {order_[i].cost, i};
    const uint32_t parts = uint32_t(std::min<size_t>(
        kMaxParts, tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
    if (parallel && parts > 1 && end >= kParallelMin && alive_triangles_ > target + 2 * size_t(end))
      collapsed += collapse_in_parts(parts, end);
    Scratch& s = serial_;
    s.region = kAnyRegion;
    for (uint32_t k = 0; k < end; ++k) {
      const uint32_t i = sorted_[k].slot;
      if (order_[i].cost > limit || alive_triangles_ - s.removed_triangles <= target) break;
      if (!small_) prefetch(sorted_.data(), k, end);
      Plan p;
      if (plan_listed(i, p) && try_collapse(p, s) == Outcome::kCollapsed) ++collapsed;
    }
    gather(s);
    return collapsed;
  }

  // The serial part's candidates (sorted_[0, end)) on `parts` cores first, with the serial loop's result. The
  // vertex numbers (Morton order) are cut into `parts` runs; a candidate belongs to the parts of its edge's
  // ends and their wedges. Each part walks its candidates in cost order and tries one only when every vertex
  // of the faces around its ends, and of its ends' wedge rings, is in the part and not blocked; else, or when
  // it belongs to several parts, the candidate is deferred to the serial loop and the part blocks its ends'
  // wedges. A collapse reads and writes only the faces around its ends (and wedges), the data of those
  // faces' vertices and its slot, and a candidate whose face was renamed is skipped (the new end is
  // touched), so a walked collapse shares nothing with a deferred candidate before it (whose ends are
  // blocked, or in another part, as are the ends of a deferred one that renamed its face) nor with another
  // part's walked collapses: they commute, and the walks then the serial loop give the serial loop's
  // collapses, bit for bit. The caller calls it only while the candidates cannot reach the target (at most
  // two triangles each): the serial loop stops there in cost order. Leaves the deferred candidates in
  // sorted_[0, end), in cost order; returns the walks' collapses. O(candidates x their faces). elephant_1m
  // 0.1 on two cores: collapses in the serial loop 43,638 -> 3,619 (of 640,282); callgrind, the collapse
  // loop's serial instructions 445 -> 76 M, the whole command 15,282 -> 15,413 M (the walks' face checks).
  static constexpr uint32_t kMaxParts = 32;  // a candidate's parts are bits of a word
  size_t collapse_in_parts(uint32_t parts, uint32_t& end) {
    const size_t m = source_.size();
    auto part_of = [&](uint32_t v) { return uint32_t(uint64_t(v) * parts / m); };
    auto ring = [&](uint32_t v, auto&& f) {
      uint32_t w = v;
      do f(w), w = wedge_[w];
      while (w != v);
    };
    // The lists, each in cost order: per part, its candidates' sorted_ entries and their edges' ends as the
    // faces hold them now (dead faces stay dead: the serial loop would skip them); `shared` when a
    // candidate belongs to several parts.
    struct Listed {
      Ranked entry;
      uint32_t i, j;
      bool shared;
    };
    // Each candidate's ends and parts (a mask; 0 when its face is dead) on every core (random reads), then
    // the lists in order.
    std::vector<uint32_t> mask(end), start(parts + 1, 0);
    std::vector<std::pair<uint32_t, uint32_t>> ends(end);
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, end, 1024), [&](const auto& r) {
      for (uint32_t k = r.begin(); k < r.end(); ++k) {
        const uint32_t slot = order_[sorted_[k].slot].slot;
        mask[k] = 0;
        if (indices_[slot - slot % 3] == kNone) continue;
        ends[k] = edge(slot);
        ring(ends[k].first, [&](uint32_t w) { mask[k] |= 1u << part_of(w); });
        ring(ends[k].second, [&](uint32_t w) { mask[k] |= 1u << part_of(w); });
      }
    });
    for (uint32_t k = 0; k < end; ++k)
      for (uint32_t bits = mask[k]; bits; bits &= bits - 1) ++start[std::countr_zero(bits) + 1];
    for (uint32_t h = 0; h < parts; ++h) start[h + 1] += start[h];
    std::vector<Listed> listed_in(start[parts]);
    {
      std::vector<uint32_t> at(start.begin(), start.end() - 1);
      for (uint32_t k = 0; k < end; ++k)
        for (uint32_t bits = mask[k]; bits; bits &= bits - 1)
          listed_in[at[std::countr_zero(bits)]++] = {sorted_[k], ends[k].first, ends[k].second,
                                                     std::popcount(mask[k]) > 1};
    }
    std::vector<Ranked> list(listed_in.size());
    for (size_t k = 0; k < list.size(); ++k) list[k] = listed_in[k].entry;
    blocked_.assign(m, 0);
    parts_.resize(parts);
    std::atomic<size_t> count{0};
    tbb::parallel_for(uint32_t(0), parts, [&](uint32_t h) {
      Scratch& s = parts_[h].scratch;
      std::vector<Ranked>& deferred = parts_[h].deferred;
      deferred.clear();
      s.region = kAnyRegion;
      auto block = [&](uint32_t v) {
        ring(v, [&](uint32_t w) {
          if (part_of(w) == h) blocked_[w] = 1;
        });
      };
      auto clear = [&](uint32_t v) { return part_of(v) == h && !blocked_[v]; };
      auto faces_clear = [&](uint32_t v) {
        bool ok = true;
        ring(v, [&](uint32_t w) { ok = ok && clear(w); });
        if (ok)
          for_faces(v, [&](uint32_t f) {
            const uint32_t* t = &indices_[3 * size_t(f)];
            ok = ok && clear(t[0]) && clear(t[1]) && clear(t[2]);
          });
        return ok;
      };
      size_t here = 0;
      for (uint32_t k = start[h]; k < start[h + 1]; ++k) {
        prefetch(list.data(), k, start[h + 1]);
        const Listed& e = listed_in[k];
        if (e.shared) {
          block(e.i), block(e.j);
          if (part_of(e.i) == h) deferred.push_back(e.entry);
          continue;
        }
        const Candidate c = listed(order_[e.entry.slot].slot);
        if (c.a == kNone || touched_[c.a] || touched_[c.b]) continue;  // skipped by the serial loop too
        if (!faces_clear(c.a) || !faces_clear(c.b)) {
          block(c.a), block(c.b);
          deferred.push_back(e.entry);
          continue;
        }
        Plan p;
        if (plan_listed(e.entry.slot, p) && try_collapse(p, s) == Outcome::kCollapsed) ++here;
      }
      count += here;
    });
    end = 0;
    for (Part& part : parts_) {
      gather(part.scratch);
      std::copy(part.deferred.begin(), part.deferred.end(), sorted_.data() + end);
      end += uint32_t(part.deferred.size());
    }
    std::sort(sorted_.data(), sorted_.data() + end,
              [](const Ranked& x, const Ranked& y) { return x.slot < y.slot; });
    return count;
  }

  // The plan of order_ entry i for the collapse loop; false when it is skipped: its face died, an end (or a
  // seam twin's) was touched by an earlier collapse of the pass, or the kind rules forbid it.
  bool plan_listed(uint32_t i, Plan& p) const {
    const Candidate c = listed(order_[i].slot);
    if (c.a == kNone || touched_[c.a] || touched_[c.b] || !can_remove(c.a, c.b, p)) return false;
    p.slot = order_[i].slot;
    return p.a2 == kNone || (!touched_[p.a2] && !touched_[p.b2]);
  }

  uint32_t region_of(uint32_t v) const { return (v + region_shift_) / region_vertices_; }
  // region_of(v) == s.region without the division (the try's hot path checks every corner around it):
  // v + shift - base wraps to above the run when v lies before the region.
  bool in_region(uint32_t v, const Scratch& s) const {
    return uint32_t(v + region_shift_ - s.region_base) < region_vertices_;
  }

  // Groups the pass's candidates by region into sorted_ as (cost, order_ index), in cost order within each
  // region (a counting_sort on both cores; candidates whose ends lie in two regions are left out) and sets
  // region_start_; pending_ = 1 (for the serial part) for every candidate until a region takes it. Turns
  // region_shift_.
  void group_by_region() {
    const size_t shrink = welded_triangles_ / std::max<size_t>(alive_triangles_, 1);
    const size_t first = std::clamp<size_t>(source_.size() / kMinRegions, 1, kRegionVertices);
    region_vertices_ = uint32_t(first * std::clamp<size_t>(shrink, 1, 1024));
    region_shift_ = (region_shift_ + region_vertices_ / 3 + 1) % region_vertices_;
    const uint32_t regions = region_of(uint32_t(source_.size())) + 1;
    const size_t n = order_.size();
    sorted_.resize(n);
    // Each candidate's region, read from its face once (counting_sort calls key twice) and looked up
    // kRegionAhead candidates ahead: order_ is in cost order, so the faces are random reads, most of them
    // cache misses (this sort took about as long as gather_candidates). Only the edge's ends are read (all
    // faces are alive at the start of a pass, and the region does not depend on the direction): the slot
    // itself was a second miss per candidate.
    constexpr size_t kRegionAhead = 16;
    UninitializedVector<uint32_t> region(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const auto& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        if (i + kRegionAhead < r.end()) __builtin_prefetch(&indices_[order_[i + kRegionAhead].slot]);
        const auto [a, b] = edge(order_[i].slot);
        const uint32_t ra = region_of(a);
        region[i] = ra == region_of(b) ? ra : kAnyRegion;
      }
    });
    counting_sort(
        n, regions, [&](size_t i) { return region[i]; },
        [&](size_t i, uint32_t position) {
          sorted_[position] = {order_[i].cost, uint32_t(i)};
        },
        &region_start_);
    pending_.assign(n, 1);
  }

  // Candidates come in cost order, random in their region, so each try starts with cache misses on a chain of
  // loads (order_ entry, slot, the ends' offsets_, their face lists, those faces' corners). This loads each
  // link of the chain for a candidate further on in the list being walked (`list`, before `end`: a region's
  // candidates in sorted_, a part's or the serial part's), the link
  // before it having been loaded some tries earlier: order_ kOrderAhead places on, the slot kSlotAhead, the
  // ends' per-vertex data kEndAhead, their face lists kFacesAhead and those faces' indices kCornersAhead, so
  // that the misses overlap the tries between instead of stalling each one in turn. Always inlined: called,
  // it was removed as dead code by GCC 12 at -O2 (kept with -fno-tree-dce), so the collapse loop had no
  // prefetch instruction at all.
  [[gnu::always_inline]] void prefetch(const Ranked* list, uint32_t k, uint32_t end) const {
    constexpr uint32_t kOrderAhead = 32, kSlotAhead = 16, kEndAhead = 8, kFacesAhead = 4, kCornersAhead = 2;
    auto candidate = [&](uint32_t ahead) { return listed(order_[list[k + ahead].slot].slot); };
    if (k + kOrderAhead < end) __builtin_prefetch(&order_[list[k + kOrderAhead].slot]);
    if (k + kSlotAhead < end) {
      const uint32_t s = order_[list[k + kSlotAhead].slot].slot;
      __builtin_prefetch(&slots_[s]), __builtin_prefetch(&indices_[s - s % 3]);
    }
    if (k + kEndAhead < end) {
      const Candidate c = candidate(kEndAhead);
      for (uint32_t v : {c.a, c.b}) {
        if (v == kNone) break;
        __builtin_prefetch(&touched_[v]), __builtin_prefetch(&offsets_[v]), __builtin_prefetch(&pos_[v]);
        __builtin_prefetch(&quadric_[v]), __builtin_prefetch(&radius_[v]), __builtin_prefetch(&pid_[v]);
        __builtin_prefetch(&wedge_[v]);
        // A quadric (44 bytes) and a vertex's attribute terms (16 bytes per channel) often end in the next
        // cache line: their last bytes too.
        __builtin_prefetch(reinterpret_cast<const char*>(&quadric_[v] + 1) - 1);
        if (channels_ > 0) {
          const AttributeTerm* t = &attr_[v * size_t(channels_)];
          __builtin_prefetch(t), __builtin_prefetch(reinterpret_cast<const char*>(t + channels_) - 1);
        }
      }
    }
    if (k + kFacesAhead < end) {
      const Candidate c = candidate(kFacesAhead);
      for (uint32_t v : {c.a, c.b})
        if (v != kNone && offsets_[v + 1] > offsets_[v])
          __builtin_prefetch(&faces_[offsets_[v]]), __builtin_prefetch(&faces_[offsets_[v + 1] - 1]);
    }
    if (k + kCornersAhead < end) {
      const Candidate c = candidate(kCornersAhead);
      for (uint32_t v : {c.a, c.b}) {
        if (v == kNone) break;
        for (uint32_t s = offsets_[v]; s < offsets_[v + 1]; ++s)
          __builtin_prefetch(&indices_[3 * size_t(faces_[s])]);
      }
    }
  }

  // Adds a thread's changes to the mesh's totals and clears them.
  void gather(Scratch& s) {
    alive_triangles_ -= s.removed_triangles;
    error_limited_ = error_limited_ || s.error_limited;
    rejected_ = rejected_ || s.rejected;
    s.removed_triangles = 0, s.error_limited = false, s.rejected = false;
  }

  // The cost of rank `goal` (0-based) among the valid candidates in slots_, or +inf when there are no more
  // than `goal` of them: a radix select on the float bits (costs are >= 0, so their bits order like them),
  // a histogram of the top bits, then nth_element within the one bucket that holds the rank. Two scans of
  // slots_ and a sort of one bucket, instead of a selection over every candidate. 4096 buckets (12 bits),
  // blocks of slots on every core; on a small mesh 1024 (11 bits: quarter binades), serially. There one
  // nth_element over every valid cost was about half of this function's time, most of it in its partition
  // loop (elephant_1m bake, perf: this function 2.04-2.34 -> 1.04-1.16 % of the samples, 3 runs; callgrind,
  // refined_elephant: 23.9 -> 22.5 M instructions).
  float goal_cost(size_t goal) {
    constexpr uint32_t kFinite = 0x7f7fffffu;  // the largest finite cost's bits: valid slots
    const int shift = small_ ? 21 : 20;
    const uint32_t buckets = (kFinite >> shift) + 1;
    const size_t blocks = std::max<size_t>(1, (slots_.size() + kSlotBlock - 1) / kSlotBlock);
    auto block_slots = [&](size_t b, uint32_t lo, uint32_t hi, auto&& f) {
      for_slots_in(slots_.data(), b * kSlotBlock, std::min(slots_.size(), (b + 1) * kSlotBlock), lo, hi, f);
    };
    // A histogram per block (for_each: serially on a small mesh), summed into the first.
    histograms_.assign(blocks * size_t(buckets), 0);
    for_each(size_t(0), blocks, [&](size_t b) {
      uint32_t* c = &histograms_[b * buckets];
      block_slots(b, 0, kFinite, [&](size_t i) { ++c[slots_[i].cost_bits() >> shift]; });
    });
    uint32_t* const count = histograms_.data();
    for (size_t b = 1; b < blocks; ++b)
      for (size_t k = 0; k < buckets; ++k) count[k] += histograms_[b * buckets + k];
    uint32_t bucket = 0;
    while (bucket < buckets && goal >= count[bucket]) goal -= count[bucket++];
    if (bucket == buckets) return std::numeric_limits<float>::infinity();
    // The valid slots in the bucket (bucket <= kFinite >> shift: it holds valid ones), the first block's
    // in bucket_, in any order: the value of rank `goal` does not depend on it.
    const uint32_t lo = bucket << shift, hi = lo | ((1u << shift) - 1);
    std::vector<std::vector<float>> found(blocks - 1);  // the later blocks'
    bucket_.clear();
    for_each(size_t(0), blocks, [&](size_t b) {
      std::vector<float>& f = b == 0 ? bucket_ : found[b - 1];
      block_slots(b, lo, hi, [&](size_t i) { f.push_back(slots_[i].cost()); });
    });
    for (const auto& f : found) bucket_.insert(bucket_.end(), f.begin(), f.end());
    std::nth_element(bucket_.begin(), bucket_.begin() + goal, bucket_.end());
    return bucket_[goal];
  }

  // f(face) for each alive face around v's wedges. Always inlined: try_collapse's AVX2 version left it two
  // calls (elephant_1m 0.1: 31 M instructions).
  template <class F>
  [[gnu::always_inline]] void for_faces(uint32_t v, F&& f) const {
    uint32_t w = v;
    do {
      for (uint32_t s = offsets_[w]; s < offsets_[w + 1]; ++s) {
        uint32_t face = faces_[s];
        if (indices_[3 * size_t(face)] != kNone) f(face);
      }
      w = wedge_[w];
    } while (w != v);
  }

  // Validity (link condition, boundary pinch, lost surface, normal change), bound, then the collapse. The
  // topological checks come first: they do not need the placement, which `place` computes only for the
  // collapses that pass them. The faces around a and b are walked once (into s.star_a, s.star_b); the
  // later steps read those lists. With a region in `s`, a collapse whose faces (those around a and b) are not
  // all inside it is left alone (kOutsideRegion): two threads then never read or write the same face or
  // vertex. A rejected collapse sets its slot to +inf until an end is touched (rejected_slot).
  LODSTREAM_HOT_PATH Outcome try_collapse(Plan& p, Scratch& s) {
    const uint32_t pa = pid_[p.a], pb = pid_[p.b];

    s.na.clear(), s.nb.clear(), s.apex.clear(), s.removed.clear(), s.star_a.clear(), s.star_b.clear();
    size_t kept_faces = 0;
    bool inside = true;
    uint64_t na_bits = 0;  // bit v % 64 for each v in s.na (the link condition's filter below)
    auto face_in_region = [&](const uint32_t* t) {
      return s.region == kAnyRegion || (in_region(t[0], s) && in_region(t[1], s) && in_region(t[2], s));
    };
    auto at = [](const uint32_t* q, uint32_t v) {
      return uint8_t((q[0] == v) | (q[1] == v) << 1 | (q[2] == v) << 2);
    };
    for_faces(p.a, [&](uint32_t f) {
      const uint32_t* t = &indices_[3 * size_t(f)];
      inside = inside && face_in_region(t);
      uint32_t q[3] = {pid_[t[0]], pid_[t[1]], pid_[t[2]]};
      const StarFace& star = s.star_a.emplace_back(StarFace{f, at(q, pa), at(q, pb)});
      if (star.at_b) {
        s.removed.push_back(f);
        for (uint32_t x : q)
          if (x != pa && x != pb) s.apex.push_back(x);
      } else {
        ++kept_faces;
        for (uint32_t x : q)
          if (x != pa) s.na.push_back(x), na_bits |= uint64_t(1) << (x % 64);
      }
    });
    for_faces(p.b, [&](uint32_t f) {
      const uint32_t* t = &indices_[3 * size_t(f)];
      inside = inside && face_in_region(t);
      uint32_t q[3] = {pid_[t[0]], pid_[t[1]], pid_[t[2]]};
      const StarFace& star = s.star_b.emplace_back(StarFace{f, at(q, pa), at(q, pb)});
      if (star.at_a) return;
      ++kept_faces;
      for (uint32_t x : q)
        if (x != pb) s.nb.push_back(x);
    });
    if (!inside) return Outcome::kOutsideRegion;
    const size_t expected = p.a2 == kNone ? (kind_[p.a] == kManifold ? 2 : 1) : 2;
    if (s.removed.size() == 0 || s.removed.size() > expected || s.apex.size() != s.removed.size())
      return rejected_slot(p, s);
    if (s.apex.size() == 2 && s.apex[0] == s.apex[1]) return rejected_slot(p, s);
    const bool interior = kind_[p.a] == kManifold && kind_[p.b] == kManifold;
    if (kept_faces < (interior ? 3u : 1u)) return rejected_slot(p, s);
    // Link condition: the neighbours a and b share are exactly the apexes of the removed faces; each apex
    // keeps an edge to x (else a removed face's image would be a dangling edge and the bound would fail).
    // The neighbour lists hold a few dozen entries: linear search, no per-vertex marks. Most of b's
    // neighbours are not a's (only the apexes are, in a valid collapse): a clear bit of na_bits rules v out
    // of s.na without the search.
    auto has = [](const std::vector<uint32_t>& list, uint32_t v) {
      return std::find(list.begin(), list.end(), v) != list.end();
    };
    for (uint32_t v : s.nb)
      if ((na_bits >> (v % 64) & 1) && has(s.na, v) && !has(s.apex, v)) return rejected_slot(p, s);
    for (uint32_t c : s.apex)
      if (!has(s.na, c) && !has(s.nb, c)) return rejected_slot(p, s);

    if (small_)
      p.x = placed_[p.slot], p.move = moves(p);  // as placed with the cost (placed_)
    else
      place(p);
    const glm::vec3 x(p.x);  // as stored: the bounds use the rounded position
    const double da = glm::length(glm::dvec3(pos_[p.a]) - glm::dvec3(x));
    const double db = glm::length(glm::dvec3(pos_[p.b]) - glm::dvec3(x));
    const double r_natural = std::max(radius_[p.a] + da, radius_[p.b] + db);

    // Normal change of every face that stays and moves (inlined into both loops: GCC 12 left it a call).
    const float cos_max = std::cos(glm::radians(opt_.max_normal_change_deg));
    bool ok = true;
    auto check = [&](const StarFace& star) __attribute__((always_inline)) {
      if (!ok || (star.at_a && star.at_b)) return;
      const uint32_t* t = &indices_[3 * size_t(star.face)];
      glm::vec3 p0 = pos_[t[0]], p1 = pos_[t[1]], p2 = pos_[t[2]];
      glm::vec3 n0 = glm::cross(p1 - p0, p2 - p0);
      glm::vec3 c[3] = {p0, p1, p2};
      for (int k = 0; k < 3; ++k)
        if ((star.at_a | star.at_b) >> k & 1) c[k] = x;
      glm::vec3 n1 = glm::cross(c[1] - c[0], c[2] - c[0]);
      float l0 = glm::length(n0), l1 = glm::length(n1);
      if (!(l0 > 1e-30f)) return;  // already degenerate in the input: nothing to flip
      if (!(l1 > 1e-6f * l0) || glm::dot(n0, n1) <= cos_max * l0 * l1) ok = false;
    };
    for (const StarFace& star : s.star_a) check(star);
    if (p.move)
      for (const StarFace& star : s.star_b) check(star);
    if (!ok) return rejected_slot(p, s);
    // The vertical bound is the smaller on all but 15 of elephant_1m 0.1's 640,282 collapses, and it is
    // needed even where the natural one stays under the bound so far: radii feed the later collapses' bounds
    // (skipping it there: elephant_1m 0.1 bound +39 %, horse 2.1x).
    const double r_new = std::min(r_natural, vertical_bound(p, x, s, r_natural));
    if (r_new > max_error_) {
      s.error_limited = true;
      return rejected_slot(p, s);
    }

    // Apply.
    for (uint32_t f : s.removed) indices_[3 * size_t(f)] = kNone;
    for (const StarFace& star : s.star_a) {
      uint32_t* t = &indices_[3 * size_t(star.face)];
      if (t[0] == kNone) continue;  // removed just now
      for (int k = 0; k < 3; ++k) {
        if (t[k] == p.a) t[k] = p.b;
        if (p.a2 != kNone && t[k] == p.a2) t[k] = p.b2;
      }
    }
    s.removed_triangles += s.removed.size();
    merge(p.a, p.b, p);
    if (p.a2 != kNone) merge(p.a2, p.b2, p);
    const glm::dvec3 to_x = glm::dvec3(x) - origin_of(p.b);
    uint32_t v = p.b;
    do {
      radius_[v] = float(r_new);
      if (p.move) rebase(v, to_x), pos_[v] = x, moved_[v] = 1;
      touched_[v] = 1;
      v = wedge_[v];
    } while (v != p.b);
    touched_[p.a] = 1;
    if (p.a2 != kNone) touched_[p.a2] = 1;
    s.bound = std::max(s.bound, r_new);
    if (record_) {  // serial (collapse_in_order): s.bound is the mesh's bound
      const float e = reported(s.bound);
      record_->push_back({p.a, p.b, step_, e});
      if (p.a2 != kNone) record_->push_back({p.a2, p.b2, step_, e});
      ++step_;
    }
    return Outcome::kCollapsed;
  }

  // Sets the candidate's slot (in a face around a and b) to +inf: it is not tried again until an end is
  // touched and re-evaluates it, or a pass that collapses nothing re-evaluates every edge.
  Outcome rejected_slot(const Plan& p, Scratch& s) {
    slots_[p.slot] = Slot::none();
    s.rejected = true;
    return Outcome::kRejected;
  }

  // Radius of x under the vertical mapping (simplify.hpp), or +inf where it does not apply or would not be
  // below `cap`. The changed
  // region (a's faces, and b's when x moves) must be a closed star at the position level whose old and new
  // faces all project with positive orientation onto the plane of its mean normal n: both then cover the
  // same region of that plane, and the mapping pairs the points over the same place, |p' - p| = the height
  // gap. The invariant needs r_new(p') >= gap(p) + r_old(p) everywhere; new radii are linear per new face and
  // the right side is piecewise linear and concave-kinked over the common refinement of both fans, so it is
  // enough to check the refinement's vertices: x in the old fan, a (and b) in the new fan, and the crossings
  // of old edges at a or b with the new edges at x (ring vertices are shared and hold trivially).
  LODSTREAM_HOT_PATH double vertical_bound(const Plan& p, const glm::vec3& x, Scratch& sc, double cap) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    auto closed = [&](uint32_t v) { return kind_[v] == kManifold || kind_[v] == kSeam; };
    if (!closed(p.a) || (p.move && !closed(p.b))) return kInf;
    // The scratch arrays only grow (to the largest star so far), and records are written in place: no
    // capacity test per record (elephant_1m 0.1, whole command: 16,597 -> 16,135 M instructions).
    auto room = [](auto& v, size_t n) {
      if (v.size() < n) v.resize(n);
      return v.data();
    };
    glm::dvec3 nsum(0.0);
    // a's faces, then (when x moves) b's that are not also a's: one loop, each record filled in place.
    const size_t na = sc.star_a.size(), nab = na + (p.move ? sc.star_b.size() : 0);
    Corners* const records = room(sc.old, nab);
    size_t faces = 0;
    for (size_t i = 0; i < nab; ++i) {
      const StarFace& star = i < na ? sc.star_a[i] : sc.star_b[i - na];
      if (i >= na && star.at_a) continue;
      const uint32_t* t = &indices_[3 * size_t(star.face)];
      Corners& c = records[faces++];
      for (int k = 0; k < 3; ++k) c.p[k] = glm::dvec3(pos_[t[k]]), c.r[k] = radius_[t[k]];
      c.moving = star.at_a | star.at_b;
      c.last_moving = std::bit_width(c.moving) - 1;
      c.dies = (c.moving & (c.moving - 1)) != 0;  // two moving corners or more
      nsum += glm::cross(c.p[1] - c.p[0], c.p[2] - c.p[0]);
    }
    const std::span<Corners> old(records, faces);
    const double len = glm::length(nsum);
    if (!(len > 0)) return kInf;
    const glm::dvec3 n = nsum / len;
    const glm::dvec3 u =
        glm::normalize(glm::cross(n, std::abs(n.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    const glm::dvec3 w = glm::cross(n, u);
    // q's projection (u.q, w.q) and height n.q in the lanes of one vector (one register in the AVX2
    // version): the three glm::dot in three multiplications and two additions, each lane in glm::dot's
    // order ((x + y) + z), so the same bits (horse 0.1 callgrind: vertical_bound 224.6 -> 215.5 M
    // instructions). The fourth lane repeats n's: a zero there had GCC 12 copy registers with the vmovq
    // form valgrind 3.19 cannot decode.
    const WideLanes lift_x{u.x, w.x, n.x, n.x}, lift_y{u.y, w.y, n.y, n.y}, lift_z{u.z, w.z, n.z, n.z};
    auto lift = [&](const glm::dvec3& q, glm::dvec2& y, double& h) __attribute__((always_inline)) {
      const WideLanes l = lift_x * q.x + lift_y * q.y + lift_z * q.z;
      y = glm::dvec2(l[0], l[1]), h = l[2];
    };
    auto cross2 = [](glm::dvec2 e, glm::dvec2 f) { return e.x * f.y - e.y * f.x; };
    const glm::dvec3 xd(x);
    glm::dvec2 yx;
    double hx;
    lift(xd, yx, hx);
    for (Corners& c : old) {
      for (int k = 0; k < 3; ++k) lift(c.p[k], c.y[k], c.h[k]);
      c.area = cross2(c.y[1] - c.y[0], c.y[2] - c.y[0]);
      if (!(c.area > 0)) return kInf;
      if (c.dies) continue;
      for (int k = 0; k < 3; ++k) c.ny[k] = c.y[k];
      c.ny[c.last_moving] = yx;
      c.new_area = cross2(c.ny[1] - c.ny[0], c.ny[2] - c.ny[0]);
      if (!(c.new_area > 0)) return kInf;
    }
    // Barycentric coordinates of q in triangle y of twice the area `area` (true when inside, with a little
    // tolerance).
    auto inside = [&](const glm::dvec2* y, double area, glm::dvec2 q, double* l) {
      l[0] = cross2(y[1] - q, y[2] - q) / area;
      l[1] = cross2(y[2] - q, y[0] - q) / area;
      l[2] = 1 - l[0] - l[1];
      return l[0] >= -1e-9 && l[1] >= -1e-9 && l[2] >= -1e-9;
    };
    double need = 0;
    // x over the old fan.
    bool found = false;
    for (const Corners& c : old) {
      double l[3];
      if (!inside(c.y, c.area, yx, l)) continue;
      need = std::abs(hx - (l[0] * c.h[0] + l[1] * c.h[1] + l[2] * c.h[2])) + l[0] * c.r[0] + l[1] * c.r[1] +
             l[2] * c.r[2];
      found = true;
      break;
    }
    if (!found || need >= cap) return kInf;
    // Requirement mu_x r_x + rest >= rhs at a point of a new face: a lower bound on r_x.
    // False when it cannot hold, or when r_x would reach `cap` (the natural bound, which then wins anyway).
    auto require = [&](double mu_x, double rest, double rhs) {
      if (mu_x > 1e-7) need = std::max(need, (rhs - rest) / mu_x);
      return (mu_x > 1e-7 || rest >= rhs - 1e-9) && need < cap;
    };
    // The moved old vertices over the new fan.
    for (uint32_t v : {p.a, p.b}) {
      if (v == p.b && !p.move) break;
      const glm::dvec3 pv(pos_[v]);
      glm::dvec2 yv;
      double hv;
      lift(pv, yv, hv);
      found = false;
      for (const Corners& c : old) {
        if (c.dies) continue;
        double l[3];
        if (!inside(c.ny, c.new_area, yv, l)) continue;
        double h = 0, rest = 0, mu_x = 0;
        for (int k = 0; k < 3; ++k) {
          h += l[k] * (c.moving >> k & 1 ? hx : c.h[k]);
          if (c.moving >> k & 1)
            mu_x += l[k];
          else
            rest += l[k] * c.r[k];
        }
        if (!require(mu_x, rest, std::abs(h - hv) + radius_[v])) return kInf;
        found = true;
        break;
      }
      if (!found) return kInf;
    }
    // Old edges at a or b against new edges at x: both lists once, then every pair (division-free rejection
    // first: most pairs do not cross).
    // At most three old edges per face (one per moving corner), one spoke per face, and three zero spokes
    // after the last (below).
    CornerRef* const old_edges = room(sc.old_edges, 3 * faces);
    CornerRef* const spoke = room(sc.spokes, faces);
    double *const spoke_x = room(sc.spoke_x, faces + 3), *const spoke_y = room(sc.spoke_y, faces + 3);
    size_t edges = 0, spokes = 0;
    constexpr int kNext[3] = {1, 2, 0};
    // Each edge at a or b leaves a or b in exactly one of its faces; a face that stays has one moving corner
    // i, and its new edge x -> ring vertex j is that face's spoke (once per spoke).
    for (const Corners& c : old) {
      auto old_edge = [&](int i) { old_edges[edges++] = {&c, i}; };
      if (c.dies) {
        for (int i = 0; i < 3; ++i)
          if (c.moving >> i & 1) old_edge(i);
        continue;
      }
      const int i = c.last_moving, j = kNext[i];
      old_edge(i);
      const glm::dvec2 d = c.y[j] - yx;
      spoke[spokes] = {&c, j};
      spoke_x[spokes] = d.x, spoke_y[spokes] = d.y, ++spokes;
    }
    // Up to three zero spokes fill the last step: den = 0 fails the first test. Four lanes where this runs
    // as vertical_bound's AVX2 version (the machine the loader picked it for).
    const bool wide = LODSTREAM_RUNS_AVX2();
    // Three stores each: as a loop from `spokes`, GCC 12 unrolled it with a remainder, 70 instructions a
    // call (elephant_1m 0.1 callgrind: that line 44.8 M; vertical_bound 3,076.5 -> 3,058.6 M).
    spoke_x[spokes] = spoke_x[spokes + 1] = spoke_x[spokes + 2] = 0.0;
    spoke_y[spokes] = spoke_y[spokes + 1] = spoke_y[spokes + 2] = 0.0;
    // The largest double below 1e-30: den > tiny is den >= 1e-30.
    const double tiny = std::nextafter(1e-30, 0.0);
    for (const CornerRef& o : std::span(old_edges, edges)) {
      const Corners& oc = *o.c;
      const int i = o.k, j = kNext[i];
      const glm::dvec2 direction = oc.y[j] - oc.y[i];
      const glm::dvec2 rel = oc.y[i] - yx;
      // s = cross2(rel, od) / den, t = cross2(rel, nd) / den, both strictly inside (0, 1), with den =
      // cross2(nd, od). sn is the same for every spoke, so its sign fixes den's: negating od, sn and tn
      // (exact) makes it positive and leaves s and t as they are, so the tests are sn < den and 0 < tn < den
      // (spoke ends on the other side of the old edge's line than x, old edge's origin on the spoke's left).
      const double sign = cross2(rel, direction) > 0 ? 1.0 : -1.0;
      const double sn = sign * cross2(rel, direction), dx = sign * direction.x, dy = sign * direction.y;
      if (sn == 0) continue;
      // tn = sign cross2(rel, nd) = cross2(sign rel, nd): negation commutes with rounding (a zero may change
      // sign, which no test below tells apart).
      const double rx = sign * rel.x, ry = sign * rel.y;
      // The tests for up to 64 spokes at a time (passing_spokes), then the crossings among them in order.
      const double threshold = std::max(sn, tiny);  // den > sn and den >= 1e-30
      for (size_t k0 = 0; k0 < spokes; k0 += 64) {
        const size_t k1 = std::min(spokes, k0 + 64);
        const uint64_t any = wide ? passing_spokes<4>(spoke_x, spoke_y, k0, k1, dx, dy, rx, ry, threshold)
                                  : passing_spokes<2>(spoke_x, spoke_y, k0, k1, dx, dy, rx, ry, threshold);
        for (uint64_t crossing = any; crossing != 0; crossing &= crossing - 1) {
          const size_t k = k0 + size_t(__builtin_ctzll(crossing));
          const Corners& ec = *spoke[k].c;
          const int ej = spoke[k].k;
          const double den = spoke_x[k] * dy - spoke_y[k] * dx;
          const double tn = rx * spoke_y[k] - ry * spoke_x[k];
          const double s = sn / den, t = tn / den;
          if (!(s > 0 && s < 1 && t > 0 && t < 1)) continue;
          const double gap = std::abs((1 - s) * hx + s * ec.h[ej] - ((1 - t) * oc.h[i] + t * oc.h[j]));
          if (!require(1 - s, s * ec.r[ej], gap + (1 - t) * oc.r[i] + t * oc.r[j])) return kInf;
        }
      }
    }
    return need;
  }

  // Merges quadrics and sets b's attributes: the attribute quadric's optimum s* = (G.x + D)/W for the
  // channels in the cost (channel_), linear interpolation along the edge for the others; half-edge collapses
  // keep b's.
  LODSTREAM_HOT_PATH void merge(uint32_t a, uint32_t b, const Plan& p) {
    const glm::dvec3 ob = origin_of(b), shift = ob - origin_of(a);
    if (p.move) {
      glm::dvec3 pa(pos_[a]), pb(pos_[b]), e = pa - pb;
      double ee = glm::dot(e, e);
      float t = ee > 0 ? float(std::clamp(glm::dot(p.x - pb, e) / ee, 0.0, 1.0)) : 0.5f;
      if (!nrm_.empty()) nrm_[b] = glm::mix(nrm_[b], nrm_[a], t);
      if (!uv_.empty()) uv_[b] = glm::mix(uv_[b], uv_[a], t);
      if (!col_.empty()) col_[b] = glm::mix(col_[b], col_[a], t);
      double w = double(quadric_[a].w) + quadric_[b].w;
      if (w > 0)
        for (int j = 0; j < channels_; ++j) {
          const AttributeTerm &ta = attr_[a * size_t(channels_) + j], &tb = attr_[b * size_t(channels_) + j];
          channel(b, j) = float((glm::dot(glm::dvec3(ta.g) + glm::dvec3(tb.g), p.x - ob) + ta.d +
                                 glm::dot(glm::dvec3(ta.g), shift) + tb.d) /
                                w / channel_[j].weight);
        }
      if (!nrm_.empty()) {
        float l = glm::length(nrm_[b]);
        nrm_[b] = l > 0 ? nrm_[b] / l : nrm_[a];
      }
      if (!col_.empty()) col_[b] = glm::clamp(col_[b], 0.0f, 1.0f);
    }
    quadric_[b].add_shifted(quadric_[a], shift);
    for (int j = 0; j < channels_; ++j) {
      const AttributeTerm& ta = attr_[a * size_t(channels_) + j];
      attr_[b * size_t(channels_) + j].g += ta.g;
      attr_[b * size_t(channels_) + j].d += float(ta.d + glm::dot(glm::dvec3(ta.g), shift));
    }
  }

  // ---- output ------------------------------------------------------------------------------------------

  // A normalized radius in model units, with room for the float rounding of scaled positions (max_error_
  // is the inverse).
  float reported(double r) const { return float(r * scale_ * (1 + 1e-5) + 1e-6 * double(scale_)); }

  void output(Result& result) {
    compact_faces();
    Mesh& out = result.mesh;
    out.material = in_.material;
    std::vector<uint32_t> remap(source_.size(), kNone);
    std::vector<uint8_t> user_locked(source_.size(), 0);
    for (size_t v = 0; v < opt_.locked.size() && v < weld_remap_.size(); ++v)
      if (opt_.locked[v]) user_locked[weld_remap_[v]] = 1;
    output_locked_.clear();
    // The invariant with the smaller maximum gives the bound (each one alone bounds the distance).
    for (uint32_t& v : indices_) {
      if (remap[v] == kNone) {
        remap[v] = uint32_t(out.positions.size());
        out.positions.push_back(moved_[v] ? pos_[v] * scale_ + origin_ : in_.positions[source_[v]]);
        if (!nrm_.empty()) out.normals.push_back(nrm_[v]);
        if (!uv_.empty()) out.uvs.push_back(uv_[v]);
        if (!col_.empty()) out.colors.push_back(col_[v]);
        result.vertex_error.push_back(radius_[v] > 0 || moved_[v] ? reported(radius_[v]) : 0.0f);
        output_locked_.push_back(user_locked[v]);
      }
      v = remap[v];
    }
    // Both surfaces lie in the union of their boxes, so its diagonal also bounds the Hausdorff distance
    // between them; plus the input's own radius against the finer surface (triangle inequality).
    Bounds both = in_.bounds();
    both.add(out.bounds());
    const float cap = float((double(both.diagonal()) + prior_error_) * (1 + 1e-6));
    for (float& e : result.vertex_error) e = std::min(e, cap);
    out.indices.assign(indices_.begin(), indices_.end());
    result.error_bound = 0.0;
    for (float e : result.vertex_error) result.error_bound = std::max(result.error_bound, double(e));
  }

 public:
  void set_record(std::vector<Collapse>* r) { record_ = r; }
  // Per output vertex: locked by Options::locked.
  std::vector<uint8_t> output_locked() const { return output_locked_; }

 private:
  std::vector<uint8_t> output_locked_;
};

}  // namespace

Result simplify_mesh(const Mesh& mesh, const Options& options) {
  Simplifier s(mesh, options);
  Result result;
  if (options.record_collapses) {
    std::vector<Collapse> record;
    s.set_record(&record);
    result = s.run();
    result.collapses = std::move(record);
  } else {
    result = s.run();
  }
  if (options.allow_topology_change && !result.target_reached) {
    Options o = options;
    o.locked = s.output_locked();
    Result clustered = cluster_mesh(result.mesh, o, result.vertex_error);
    if (clustered.mesh.triangle_count() < result.mesh.triangle_count()) {
      result.mesh = std::move(clustered.mesh);
      result.vertex_error = std::move(clustered.vertex_error);
      result.error_bound = clustered.error_bound;
      result.target_reached = clustered.target_reached;
    }
  }
  return result;
}

}  // namespace lodstream::simplify
