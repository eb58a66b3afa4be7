#include "package/index.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <optional>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/format.hpp"
#include "package/quantized_node.hpp"

namespace lodstream::package {

namespace {

// Smallest serialized node record (index.hpp, "Node records"): head, 3 field deltas, triangles, the object
// count and the two pair codes, with both link lists implied and page, offset, size and cluster those of the
// previous record's bytes (bit 5).
constexpr size_t kMinNodeRecordBytes = 8;

// A representation's kind byte: bit 7 set when its grid's origin is its bounds' minimum, bit for bit, and
// not stored (PositionGrid::for_bounds' grids are: 12 B a representation; the city's 807 representations,
// root index 57,887 -> 55,286 B stored).
constexpr uint8_t kGridOriginAtBoundsMin = 0x80;

// An error bound: non-negative, +infinity allowed (nothing replaces the node), NaN rejected.
float read_error(ByteReader& r) {
  float e = r.f32();
  if (std::isnan(e) || e < 0.0f) r.fail("invalid error bound");
  return e;
}

// A table of byte ranges (pages, blobs, index pages): each as svarint offset minus the previous range's end
// (0 for ranges stored one after another, as the writer stores each table's), varint size and raw size,
// u64 checksum: 11 bytes a range, not 24 (refined_elephant's root index 730 -> 631 B stored).
constexpr size_t kMinRangeBytes = 11;
void write_ranges(ByteWriter& w, std::span<const Range> ranges) {
  w.varint(ranges.size());
  uint64_t end = 0;
  for (const Range& range : ranges) {
    w.svarint(int64_t(range.offset - end)), w.varint(range.size), w.varint(range.raw_size),
        w.u64(range.checksum);
    end = range.offset + range.size;
  }
}
std::vector<Range> read_ranges(ByteReader& r, uint32_t max_raw, const char* what) {
  std::vector<Range> ranges(r.count(kMinRangeBytes, what));
  uint64_t end = 0;
  for (Range& range : ranges) {
    const int64_t delta = r.svarint();  // offsets below 2^63: checked before adding so that nothing overflows
    if (delta < -int64_t(end) || delta > INT64_MAX - int64_t(end))
      r.fail(std::string(what) + " offset out of range");
    range.offset = uint64_t(int64_t(end) + delta);
    range.size = r.index(uint64_t(UINT32_MAX) + 1, "range size");
    range.raw_size = r.index(uint64_t(max_raw) + 1, "raw size");
    range.checksum = r.u64();
    if (range.size > uint64_t(INT64_MAX) - range.offset) r.fail(std::string(what) + " range out of range");
    end = range.offset + range.size;
  }
  return ranges;
}

// A list of node ids (index.hpp, "Node records"): varint count, then each id as an svarint delta from the
// previous one plus 1 (the first from `base`), so that runs of consecutive ids are runs of zero bytes.
void write_id_deltas(ByteWriter& w, const std::vector<uint32_t>& ids, uint32_t base) {
  int64_t previous = int64_t(base) - 1;
  for (uint32_t id : ids) w.svarint(int64_t(id) - previous - 1), previous = id;
}
void write_ids(ByteWriter& w, const std::vector<uint32_t>& ids, uint32_t base) {
  w.varint(ids.size());
  write_id_deltas(w, ids, base);
}
// `count` ids written by write_id_deltas, each < limit.
std::vector<uint32_t> read_id_deltas(ByteReader& r, size_t count, uint32_t base, uint64_t limit,
                                     const char* what) {
  std::vector<uint32_t> ids(count);
  int64_t previous = int64_t(base) - 1;
  for (uint32_t& id : ids) {
    const int64_t delta = r.svarint();  // checked before adding so that nothing overflows
    if (delta < -(previous + 1) || delta >= int64_t(limit) - (previous + 1))
      r.fail(std::string(what) + " id out of range (" + std::to_string(limit) + " nodes)");
    id = static_cast<uint32_t>(previous + 1 + delta);
    previous = id;
  }
  return ids;
}
std::vector<uint32_t> read_ids(ByteReader& r, uint32_t base, uint64_t limit, const char* what) {
  const size_t count = r.count(1, what);
  return read_id_deltas(r, count, base, limit, what);
}

// previous + delta, which must be < limit.
uint32_t read_delta(ByteReader& r, uint32_t previous, uint64_t limit, const char* what) {
  const int64_t delta = r.svarint();
  if (delta < -int64_t(previous) || delta >= int64_t(limit) - int64_t(previous))
    r.fail(std::string(what) + " out of range");
  return static_cast<uint32_t>(int64_t(previous) + delta);
}

// An (error, sphere) pair: a node's own, or its parents'.
struct ErrorPair {
  float error = 0.0f;
  Sphere sphere;
  bool operator==(const ErrorPair& o) const {  // bit for bit (verify compares stored pairs exactly)
    return std::bit_cast<uint32_t>(error) == std::bit_cast<uint32_t>(o.error) &&
           std::bit_cast<uint32_t>(sphere.radius) == std::bit_cast<uint32_t>(o.sphere.radius) &&
           std::bit_cast<uint32_t>(sphere.center.x) == std::bit_cast<uint32_t>(o.sphere.center.x) &&
           std::bit_cast<uint32_t>(sphere.center.y) == std::bit_cast<uint32_t>(o.sphere.center.y) &&
           std::bit_cast<uint32_t>(sphere.center.z) == std::bit_cast<uint32_t>(o.sphere.center.z);
  }
};
ErrorPair own_pair(const NodeRecord& n) {
  return {n.error, n.sphere};
}
ErrorPair parent_pair(const NodeRecord& n) {
  return {n.parent_error, n.parent_sphere};
}

// The fields of a run of records, each coded into a stream of its own (index.hpp): zstd then sees each
// field's repetitions and statistics apart from the others'. In the order of kIndexFieldNames.
enum Field : size_t {
  kHead,          // head byte
  kDeltas,        // representation, material, level
  kLocation,      // page, offset
  kSize,          // size, cluster
  kTriangles,     // triangle count
  kChildren,      // children list
  kParents,       // parents list
  kObjects,       // objects list
  kPairCode,      // pair codes
  kPairError,     // pair errors
  kPairExponent,  // compact pairs' exponents
  kPairCentre,    // sphere centres
  kPairRadius,    // sphere radii
  kFields
};
static_assert(kFields == kIndexFields);
using FieldWriters = std::array<ByteWriter, kFields>;

// A run's field streams as read: one reader per field over its bytes.
struct FieldReaders {
  std::vector<std::string> contexts;
  std::vector<ByteReader> f;
  ByteReader& operator[](Field field) { return f[field]; }
};

// A compact pair (index.hpp): the error's top 24 bits (its low 8 bits zero), then the sphere as integers
// times 2^E: svarint E minus the previous compact pair's E, the centre's three integers as svarint deltas
// from floor(previous compact centre / 2^E), varint radius integer. Limits keep every integer exact in a
// double.
constexpr int kMinPairExponent = -160, kMaxPairExponent = 128;
constexpr int64_t kMaxPairInteger = int64_t(1) << 40;

// floor(v / 2^exponent), clamped to +-2^62: the reference of a compact centre (exact in double: |v| < 2^128
// and |exponent| <= 160).
int64_t grid_reference(float v, int exponent) {
  const double k = std::floor(std::ldexp(double(v), -exponent));
  return int64_t(std::clamp(k, -0x1p62, 0x1p62));
}
// The largest E with every value an integer multiple of 2^E (0 when all are zero).
int common_exponent(std::span<const float> values) {
  int e = std::numeric_limits<int>::max();
  for (float v : values) {
    if (v == 0.0f) continue;
    int ex = 0;
    const double m = std::frexp(double(v), &ex);  // v = m 2^ex, 0.5 <= |m| < 1, m has at most 24 bits
    const uint64_t bits = uint64_t(std::abs(std::ldexp(m, 53)));
    e = std::min(e, ex - 53 + std::countr_zero(bits));
  }
  return e == std::numeric_limits<int>::max() ? 0 : e;
}

// What a run of node records (the root index's, or one index page's) is coded against: its records so far,
// the distinct pairs they stored, in order of first appearance, and the last compact pair's exponent and
// centre. Cost: O(distinct pairs) per pair coded.
struct RecordRun {
  uint32_t first_id = 0;
  std::span<const NodeRecord> done;  // records first_id .. first_id + done.size() - 1
  std::vector<ErrorPair> pairs;
  int exponent = 0;
  glm::vec3 center{0.0f};

  // (child, record) for every child listed by the run's records so far and not yet reached, a min-heap:
  // records come in id order, so a child's links are taken when it comes (and dropped when it was before).
  std::vector<std::pair<uint32_t, uint32_t>> links;
  std::vector<uint32_t> derived;  // derived_parents' answer
  // The distinct non-empty children lists the run stored, in order, and where the next one is expected to
  // start: after the latest (a DAG's groups are runs of consecutive ids, often stored in order).
  std::vector<std::vector<uint32_t>> child_lists;
  std::optional<uint32_t> next_child;

  const NodeRecord& previous() const {
    static const NodeRecord none;  // every field 0
    return done.empty() ? none : done.back();
  }
  // A children list (index.hpp): varint 2k + 1 for the k-th latest of child_lists, else 2 x count, then the
  // ids as write_id_deltas from next_child (the record's id for the run's first list). Siblings' lists repeat
  // apart when their parents' records are not consecutive (refined_elephant: 120 references to 158 lists).
  void write_children(ByteWriter& w, const std::vector<uint32_t>& children, uint32_t id) {
    const auto it = std::find(child_lists.rbegin(), child_lists.rend(), children);
    if (!children.empty() && it != child_lists.rend()) {
      w.varint(2 * uint64_t(it - child_lists.rbegin()) + 1);
      return;
    }
    w.varint(2 * uint64_t(children.size()));
    write_id_deltas(w, children, next_child.value_or(id));
    add_child_list(children);
  }
  std::vector<uint32_t> read_children(ByteReader& r, uint32_t id, uint64_t limit) {
    const uint64_t code = r.varint();
    if (code & 1) {
      if ((code - 1) / 2 >= child_lists.size()) r.fail("children list reference out of range");
      return child_lists[child_lists.size() - 1 - (code - 1) / 2];
    }
    if (code / 2 > r.remaining()) r.fail("impossible child count " + std::to_string(code / 2));
    std::vector<uint32_t> children =
        read_id_deltas(r, size_t(code / 2), next_child.value_or(id), limit, "child");
    add_child_list(children);
    return children;
  }
  void add_child_list(const std::vector<uint32_t>& children) {
    if (children.empty()) return;
    child_lists.push_back(children);
    next_child = children.back() + 1;  // ids < limit <= 2^32: no wrap
  }
  // Record `id` is done: its children gain it as a parent. Cost: O(its children x log links).
  void add_links(const NodeRecord& n, uint32_t id) {
    for (uint32_t c : n.children) {
      links.emplace_back(c, id);
      std::push_heap(links.begin(), links.end(), std::greater<>());
    }
  }
  // The parents a record's head may imply (kDerivedParents): the records before it in this run whose
  // children list holds `id` (a DAG node's parents are the nodes its group was simplified into, each of which
  // lists that group as its children), in id order, or nullptr when none does. Called once per record, in id
  // order. Cost: O(links taken x log links).
  const std::vector<uint32_t>* derived_parents(uint32_t id) {
    derived.clear();
    while (!links.empty() && links.front().first <= id) {
      if (links.front().first == id) derived.push_back(links.front().second);
      std::pop_heap(links.begin(), links.end(), std::greater<>());
      links.pop_back();
    }
    return derived.empty() ? nullptr : &derived;
  }
  // The parents' pair can be taken from parents[0] when that record is already in this run.
  const NodeRecord* first_parent(const NodeRecord& n) const {
    if (n.parents.empty() || n.parents[0] < first_id || n.parents[0] - first_id >= done.size())
      return nullptr;
    return &done[n.parents[0] - first_id];
  }
  // The exponent and centre a compact pair is coded against: the parents' sphere `base` when given (a node's
  // own sphere lies inside its parents', so its centre is a few grid steps from theirs and its radius a
  // power of two or so below: the exponent is coded against ilogb of the parents' radius), else the run's
  // previous compact pair.
  std::pair<int, glm::vec3> reference(const Sphere* base) const {
    if (!base) return {exponent, center};
    return {std::isnormal(base->radius) ? std::ilogb(base->radius) : exponent, base->center};
  }
  // Writes `p` compactly and returns true when it decodes back bit for bit.
  bool write_compact(FieldWriters& w, const ErrorPair& p, const Sphere* base) {
    const uint32_t error_bits = std::bit_cast<uint32_t>(p.error);
    if ((error_bits & 0xFFu) != 0 || !std::isfinite(p.sphere.radius) || !std::isfinite(p.sphere.center.x) ||
        !std::isfinite(p.sphere.center.y) || !std::isfinite(p.sphere.center.z))
      return false;
    const std::array<float, 4> values = {p.sphere.center.x, p.sphere.center.y, p.sphere.center.z,
                                         p.sphere.radius};
    const int e = common_exponent(values);
    if (e < kMinPairExponent || e > kMaxPairExponent) return false;
    std::array<int64_t, 4> k;
    for (int a = 0; a < 4; ++a) {
      const double v = std::ldexp(double(values[a]), -e);
      if (!(std::abs(v) <= double(kMaxPairInteger)) || (a == 3 && v < 0.0)) return false;
      k[a] = int64_t(v);
      if (std::bit_cast<uint32_t>(float(std::ldexp(double(k[a]), e))) != std::bit_cast<uint32_t>(values[a]))
        return false;  // -0, or a negative radius
    }
    ByteWriter& error = w[kPairError];
    error.u8(uint8_t(error_bits >> 8)), error.u8(uint8_t(error_bits >> 16)),
        error.u8(uint8_t(error_bits >> 24));
    const auto [reference_exponent, reference_center] = reference(base);
    w[kPairExponent].svarint(e - reference_exponent);
    for (int a = 0; a < 3; ++a) w[kPairCentre].svarint(k[a] - grid_reference(reference_center[a], e));
    w[kPairRadius].varint(uint64_t(k[3]));
    exponent = e, center = p.sphere.center;
    return true;
  }
  ErrorPair read_compact(FieldReaders& r, const Sphere* base) {
    ErrorPair p;
    ByteReader& error = r[kPairError];
    uint32_t error_bits = uint32_t(error.u8()) << 8;
    error_bits |= uint32_t(error.u8()) << 16;
    error_bits |= uint32_t(error.u8()) << 24;
    p.error = std::bit_cast<float>(error_bits);
    if (std::isnan(p.error) || p.error < 0.0f) error.fail("invalid error bound");
    const auto [reference_exponent, reference_center] = reference(base);
    const int64_t de = r[kPairExponent].svarint();
    if (de < kMinPairExponent - reference_exponent || de > kMaxPairExponent - reference_exponent)
      r[kPairExponent].fail("sphere exponent out of range");
    const int e = reference_exponent + int(de);
    for (int a = 0; a < 3; ++a) {
      const int64_t delta = r[kPairCentre].svarint(), grid = grid_reference(reference_center[a], e);
      if (delta < -kMaxPairInteger - grid || delta > kMaxPairInteger - grid)
        r[kPairCentre].fail("sphere centre out of range");
      p.sphere.center[a] = float(std::ldexp(double(grid + delta), e));
    }
    const uint64_t radius = r[kPairRadius].varint();
    if (radius > uint64_t(kMaxPairInteger)) r[kPairRadius].fail("sphere radius out of range");
    p.sphere.radius = float(std::ldexp(double(radius), e));
    if (!std::isfinite(p.sphere.radius) || !std::isfinite(p.sphere.center.x) ||
        !std::isfinite(p.sphere.center.y) || !std::isfinite(p.sphere.center.z))
      r[kPairCentre].fail("sphere out of the float range");
    exponent = e, center = p.sphere.center;
    return p;
  }
  // Pair code: `skip` = a literal (error f32, sphere 4 f32), skip + 1 = a compact pair, both joining the
  // table; skip + 1 + k (k >= 1) = the k-th latest pair of the table; codes below `skip` are taken by the
  // caller.
  void write_pair(FieldWriters& w, const ErrorPair& p, uint64_t skip, const Sphere* base) {
    const auto it = std::find(pairs.rbegin(), pairs.rend(), p);
    if (it != pairs.rend()) {
      w[kPairCode].varint(skip + 2 + uint64_t(it - pairs.rbegin()));
      return;
    }
    if (write_compact(w, p, base)) {  // writes nothing when it returns false
      w[kPairCode].varint(skip + 1);
    } else {
      w[kPairCode].varint(skip);
      w[kPairError].f32(p.error);
      for (int a = 0; a < 3; ++a) w[kPairCentre].f32(p.sphere.center[a]);
      w[kPairRadius].f32(p.sphere.radius);
    }
    pairs.push_back(p);
  }
  ErrorPair read_pair(FieldReaders& r, uint64_t code, const Sphere* base) {
    if (code > 1) {
      if (code - 1 > pairs.size()) r[kPairCode].fail("error pair reference out of range");
      return pairs[pairs.size() - (code - 1)];
    }
    ErrorPair p;
    if (code == 1) {
      p = read_compact(r, base);
    } else {
      p.error = read_error(r[kPairError]);
      for (int a = 0; a < 3; ++a) p.sphere.center[a] = r[kPairCentre].finite_f32("sphere centre");
      p.sphere.radius = r[kPairRadius].finite_f32("sphere radius");
      if (p.sphere.radius < 0.0f) r[kPairRadius].fail("negative sphere radius");
    }
    pairs.push_back(p);
    return p;
  }
};

enum : uint8_t { kSameChildren = 8, kSameParents = 16, kSameRecord = 32, kDerivedParents = 64 };

void write_node(FieldWriters& w, const NodeRecord& n, uint32_t id, RecordRun& run) {
  const NodeRecord& prev = run.previous();
  const bool same_children = !run.done.empty() && n.children == prev.children;
  const bool same_parents = !run.done.empty() && n.parents == prev.parents;
  const std::vector<uint32_t>* derived = run.derived_parents(id);
  const bool derived_parents = !same_parents && derived && *derived == n.parents;
  const bool same_record = !run.done.empty() && n.page == prev.page && n.offset == prev.offset &&
                           n.size == prev.size && n.cluster == prev.cluster + 1;
  w[kHead].u8(static_cast<uint8_t>(uint8_t(n.kind) | uint8_t(n.encoding) << 2 |
                                   (same_children ? kSameChildren : 0) | (same_parents ? kSameParents : 0) |
                                   (same_record ? kSameRecord : 0) |
                                   (derived_parents ? kDerivedParents : 0)));
  w[kDeltas].svarint(int64_t(n.representation) - prev.representation);
  w[kDeltas].svarint(int64_t(n.material) - prev.material);
  w[kDeltas].svarint(int64_t(n.level) - prev.level);
  if (!same_record) {
    w[kLocation].svarint(int64_t(n.page) - prev.page);
    w[kLocation].svarint(int64_t(n.offset) - (n.page == prev.page ? int64_t(prev.offset) + prev.size : 0));
    w[kSize].varint(n.size);
    w[kSize].varint(n.cluster);
  }
  w[kTriangles].varint(n.triangles);
  if (!same_children) run.write_children(w[kChildren], n.children, id);
  if (!same_parents && !derived_parents) write_ids(w[kParents], n.parents, id);
  write_ids(w[kObjects], n.objects, 0);
  const NodeRecord* parent = run.first_parent(n);
  if (parent && own_pair(*parent) == parent_pair(n)) {
    w[kPairCode].varint(0);
  } else {
    run.write_pair(w, parent_pair(n), 1, nullptr);
  }
  run.write_pair(w, own_pair(n), 0, n.parents.empty() ? nullptr : &n.parent_sphere);
}

NodeRecord read_node(FieldReaders& r, const RootIndex& root, uint32_t id, RecordRun& run) {
  const NodeRecord& prev = run.previous();
  NodeRecord n;
  const uint8_t head = r[kHead].u8();
  if (head & ~uint8_t(3 | 4 | kSameChildren | kSameParents | kSameRecord | kDerivedParents))
    r[kHead].fail("node " + std::to_string(id) + ": unknown record flags");
  const std::vector<uint32_t>* derived = run.derived_parents(id);
  if ((head & kDerivedParents) && (head & kSameParents))
    r[kHead].fail("node " + std::to_string(id) + ": parents both implied and the previous record's");
  if ((head & kDerivedParents) && !derived)
    r[kHead].fail("node " + std::to_string(id) + ": implied parents that no record of this run lists");
  n.kind = NodeKind(head & 3), n.encoding = NodeEncoding((head >> 2) & 1);
  if ((head & (kSameChildren | kSameParents | kSameRecord)) && run.done.empty())
    r[kHead].fail("node " + std::to_string(id) + ": refers to a previous record that this run does not have");
  n.representation =
      read_delta(r[kDeltas], prev.representation, root.scene.representations.size(), "representation");
  n.material = read_delta(r[kDeltas], prev.material, root.scene.materials.size(), "material");
  n.level = read_delta(r[kDeltas], prev.level, 1u << 16, "level");
  if (head & kSameRecord) {
    n.page = prev.page, n.offset = prev.offset, n.size = prev.size, n.cluster = prev.cluster + 1;
  } else {
    n.page = read_delta(r[kLocation], prev.page, root.pages.size(), "page");
    const int64_t base = n.page == prev.page ? int64_t(prev.offset) + prev.size : 0;
    const int64_t delta = r[kLocation].svarint();  // checked before adding so that nothing overflows
    const int64_t offset = delta < -base || delta > int64_t(UINT32_MAX) ? -1 : base + delta;
    const uint64_t size = r[kSize].varint();
    if (offset < 0 || uint64_t(offset) > root.pages[n.page].raw_size ||
        size > root.pages[n.page].raw_size - uint64_t(offset)) {
      r[kSize].fail("node " + std::to_string(id) + ": bytes [" + std::to_string(offset) + ", +" +
                    std::to_string(size) + ") outside page " + std::to_string(n.page));
    }
    n.offset = uint32_t(offset), n.size = uint32_t(size);
    const uint64_t cluster = r[kSize].varint();
    n.cluster = uint32_t(std::min<uint64_t>(cluster, kMaxRecordClusters));
  }
  if (n.cluster >= kMaxRecordClusters)
    r[kSize].fail("node " + std::to_string(id) + ": cluster index of its record out of range");
  n.triangles = r[kTriangles].index(uint64_t(UINT32_MAX) + 1, "triangle count");
  n.children = head & kSameChildren ? prev.children : run.read_children(r[kChildren], id, root.node_count);
  if (head & kSameParents) {
    n.parents = prev.parents;
  } else if (head & kDerivedParents) {
    n.parents = *derived;
  } else {
    n.parents = read_ids(r[kParents], id, root.node_count, "parent");
  }
  n.objects = read_ids(r[kObjects], 0, root.scene.objects.size(), "object");
  const uint64_t code = r[kPairCode].varint();
  ErrorPair parents;
  if (code == 0) {
    const NodeRecord* parent = run.first_parent(n);
    if (!parent)
      r[kPairCode].fail("node " + std::to_string(id) + ": parents' pair refers to a record outside this run");
    parents = own_pair(*parent);
  } else {
    parents = run.read_pair(r, code - 1, nullptr);
  }
  n.parent_error = parents.error, n.parent_sphere = parents.sphere;
  const ErrorPair own =
      run.read_pair(r, r[kPairCode].varint(), n.parents.empty() ? nullptr : &n.parent_sphere);
  n.error = own.error, n.sphere = own.sphere;
  return n;
}

// The records of ids first_id.., coded as one run: for each field, varint byte count then its stream.
void write_nodes(ByteWriter& w, std::span<const NodeRecord> nodes, uint32_t first_id) {
  const std::array<std::vector<uint8_t>, kFields> fields = serialize_node_fields(nodes, first_id);
  for (const std::vector<uint8_t>& f : fields) w.varint(f.size());
  for (const std::vector<uint8_t>& f : fields) w.raw(f);
}
std::vector<NodeRecord> read_nodes(ByteReader& r, const RootIndex& root, uint32_t first_id, size_t count,
                                   std::string_view context) {
  FieldReaders fields;
  std::array<uint64_t, kFields> sizes;
  for (uint64_t& size : sizes) size = r.varint();
  fields.contexts.reserve(kFields);  // the readers keep views of these
  for (size_t f = 0; f < kFields; ++f) {
    if (sizes[f] > r.remaining()) r.fail(std::string(kIndexFieldNames[f]) + " stream longer than the run");
    fields.contexts.push_back(std::string(context) + ": " + kIndexFieldNames[f]);
    fields.f.emplace_back(r.bytes(size_t(sizes[f]), kIndexFieldNames[f]), fields.contexts.back());
  }
  std::vector<NodeRecord> nodes;  // grown as records parse (no reserve: a hostile count allocates nothing)
  RecordRun run;
  run.first_id = first_id;
  // Repeated lists (the head's same-children / same-parents flags, children list references, implied
  // parents) cost a byte or none each, so a hostile run could expand a few KB into records x list length
  // ids. The run's links (children and parents ids) are bounded by kMaxLinksPerRecord a record plus one a
  // byte read up to the run's end (in the root index, the tables before it too): linear in its size. A DAG
  // record lists its group's clusters (4-8, rarely more) and the clusters its group became; an HLOD node its
  // BVH children.
  constexpr uint64_t kMaxLinksPerRecord = 64;
  const uint64_t max_links = kMaxLinksPerRecord * count + r.position();
  uint64_t links = 0;
  for (uint32_t i = 0; i < count; ++i) {
    run.done = nodes;
    nodes.push_back(read_node(fields, root, first_id + i, run));
    links += nodes.back().children.size() + nodes.back().parents.size();
    if (links > max_links)
      throw Error(std::string(context) + ": node " + std::to_string(first_id + i) +
                  ": the run's records list " + std::to_string(links) + " links, more than its " +
                  std::to_string(count) + " records and bytes can hold (at most " +
                  std::to_string(max_links) + ")");
    run.add_links(nodes.back(), first_id + i);
  }
  for (ByteReader& f : fields.f) f.expect_end();
  return nodes;
}

}  // namespace

std::array<std::vector<uint8_t>, kIndexFields> serialize_node_fields(std::span<const NodeRecord> nodes,
                                                                     uint32_t first_id) {
  FieldWriters fields;
  RecordRun run;
  run.first_id = first_id;
  for (size_t i = 0; i < nodes.size(); ++i) {
    run.done = nodes.first(i);
    write_node(fields, nodes[i], first_id + uint32_t(i), run);
    run.add_links(nodes[i], first_id + uint32_t(i));
  }
  std::array<std::vector<uint8_t>, kIndexFields> out;
  for (size_t f = 0; f < kFields; ++f) out[f] = std::move(fields[f].bytes);
  return out;
}

std::vector<uint8_t> serialize_root(const RootIndex& root) {
  ByteWriter w;
  w.u32(root.codec);
  w.u32(root.node_count);
  w.u64(root.scene.input_triangles);
  w.string(root.scene.metadata);
  write_ranges(w, root.pages);
  write_ranges(w, root.blobs);
  w.varint(root.scene.materials.size());
  for (const PackageMaterial& m : root.scene.materials) {
    w.string(m.material.name);
    for (int a = 0; a < 4; ++a) w.f32(m.material.base_color[a]);
    w.string(m.material.base_color_texture);
    w.varint(m.texture_blob == kNone ? 0 : uint64_t(m.texture_blob) + 1);
  }
  w.varint(root.scene.representations.size());
  for (const Representation& rep : root.scene.representations) {
    const bool origin_at_min = std::memcmp(&rep.grid.origin, &rep.bounds.min, sizeof(glm::vec3)) == 0;
    w.u8(static_cast<uint8_t>(uint8_t(rep.kind) | (origin_at_min ? kGridOriginAtBoundsMin : 0)));
    w.string(rep.name);
    for (int a = 0; a < 3; ++a) w.f32(rep.bounds.min[a]);
    for (int a = 0; a < 3; ++a) w.f32(rep.bounds.max[a]);
    if (!origin_at_min)
      for (int a = 0; a < 3; ++a) w.f32(rep.grid.origin[a]);
    w.f32(rep.grid.step);
    w.varint(rep.levels);
    write_ids(w, rep.roots, 0);
  }
  w.varint(root.scene.objects.size());
  for (const ObjectRecord& o : root.scene.objects) {
    w.string(o.name);
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) w.f32(o.transform[c][r]);
    }
    w.varint(o.representation);
  }
  std::vector<Range> index_ranges;
  for (const IndexPage& p : root.index_pages) index_ranges.push_back(p.range);
  write_ranges(w, index_ranges);
  for (const IndexPage& p : root.index_pages) w.varint(p.first_node), w.varint(p.node_count);
  w.varint(root.root_nodes.size());
  write_nodes(w, root.root_nodes, 0);
  return std::move(w.bytes);
}

RootIndex parse_root(std::span<const uint8_t> raw, const std::string& context) {
  ByteReader r(raw, context);
  RootIndex root;
  root.codec = r.u32();
  try {
    node_codec(root.codec);
  } catch (const Error& e) {
    throw Error(context + ": " + e.what());
  }
  root.node_count = r.u32();
  root.scene.input_triangles = r.u64();
  root.scene.metadata = r.string("metadata");
  root.pages = read_ranges(r, kMaxPageRawBytes, "page");
  root.blobs = read_ranges(r, UINT32_MAX, "blob");
  root.scene.materials.resize(r.count(19, "material"));
  for (PackageMaterial& m : root.scene.materials) {
    m.material.name = r.string("material name");
    for (int a = 0; a < 4; ++a) m.material.base_color[a] = r.finite_f32("base colour");
    m.material.base_color_texture = r.string("texture path");
    uint32_t blob = r.index(root.blobs.size() + 1, "texture blob");
    m.texture_blob = blob == 0 ? kNone : blob - 1;
  }
  // At least kind, name, bounds, step, levels and roots: 32 bytes (the grid origin may be implied).
  root.scene.representations.resize(r.count(32, "representation"));
  for (Representation& rep : root.scene.representations) {
    const uint8_t head = r.u8();
    const uint8_t kind = head & uint8_t(~kGridOriginAtBoundsMin);
    if (kind > uint8_t(RepresentationKind::imposter_set)) r.fail("unknown representation kind");
    rep.kind = RepresentationKind(kind);
    rep.name = r.string("representation name");
    for (int a = 0; a < 3; ++a) rep.bounds.min[a] = r.finite_f32("bounds");
    for (int a = 0; a < 3; ++a) rep.bounds.max[a] = r.finite_f32("bounds");
    if (head & kGridOriginAtBoundsMin) {
      rep.grid.origin = rep.bounds.min;
    } else {
      for (int a = 0; a < 3; ++a) rep.grid.origin[a] = r.finite_f32("grid origin");
    }
    rep.grid.step = r.finite_f32("grid step");
    if (!(rep.grid.step > 0.0f)) r.fail("grid step must be positive");
    rep.levels = r.index(1u << 16, "level count");
    rep.roots = read_ids(r, 0, root.node_count, "root node");
  }
  root.scene.objects.resize(r.count(66, "object"));
  for (ObjectRecord& o : root.scene.objects) {
    o.name = r.string("object name");
    for (int c = 0; c < 4; ++c) {
      for (int rr = 0; rr < 4; ++rr) o.transform[c][rr] = r.finite_f32("transform");
    }
    o.representation = r.index(root.scene.representations.size(), "representation");
  }
  const std::vector<Range> index_ranges = read_ranges(r, kMaxIndexPageRawBytes, "index page");
  root.index_pages.resize(index_ranges.size());
  for (size_t i = 0; i < index_ranges.size(); ++i) {
    IndexPage& p = root.index_pages[i];
    p.range = index_ranges[i];
    p.first_node = r.index(uint64_t(UINT32_MAX) + 1, "first node");
    p.node_count = r.index(uint64_t(UINT32_MAX) + 1, "node count");
  }
  size_t root_nodes = r.count(kMinNodeRecordBytes, "root node record", root.node_count);
  // The index pages must cover [root_nodes, node_count) in order, each with at least one node, each node
  // record taking at least kMinNodeRecordBytes of the page.
  uint64_t next = root_nodes;
  for (size_t i = 0; i < root.index_pages.size(); ++i) {
    const IndexPage& p = root.index_pages[i];
    if (p.first_node != next || p.node_count == 0 || p.node_count > p.range.raw_size / kMinNodeRecordBytes) {
      throw Error(context + ": index page " + std::to_string(i) + " has an inconsistent node range");
    }
    next += p.node_count;
  }
  if (next != root.node_count) {
    throw Error(context + ": index pages cover " + std::to_string(next) + " nodes, the index declares " +
                std::to_string(root.node_count));
  }
  root.root_nodes = read_nodes(r, root, 0, root_nodes, context);
  r.expect_end();
  return root;
}

std::vector<uint8_t> serialize_nodes(std::span<const NodeRecord> nodes, uint32_t first_id) {
  ByteWriter w;
  write_nodes(w, nodes, first_id);
  return std::move(w.bytes);
}

std::vector<NodeRecord> parse_nodes(std::span<const uint8_t> raw, const RootIndex& root, uint32_t first_id,
                                    uint32_t count, const std::string& context) {
  ByteReader r(raw, context);
  if (count > raw.size() / kMinNodeRecordBytes) r.fail("more node records than the page can hold");
  std::vector<NodeRecord> nodes = read_nodes(r, root, first_id, count, context);
  r.expect_end();
  return nodes;
}

}  // namespace lodstream::package
