// Node records of the index (index.hpp, "Node records"): a run round-trips exactly, shared (error, sphere)
// pairs are stored once per run, compact pairs are smaller and come back bit for bit, and hostile references
// (to pairs or records the run does not have) and compact values are one-line errors.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <numeric>
#include <string_view>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/index.hpp"
#include "package/pair_rounding.hpp"
#include "package/quantized_node.hpp"

namespace lodstream::test {
namespace {

using namespace package;

// A root index whose tables the records below refer to: 2 representations, 2 materials, 3 objects, 4 pages
// of 1000 raw bytes, 64 nodes.
RootIndex tables() {
  RootIndex root;
  root.scene.representations.resize(2);
  root.scene.materials.resize(2);
  root.scene.objects.resize(3);
  root.pages.assign(4, Range{0, 10, 1000, 0});
  root.node_count = 64;
  return root;
}

// Records ids first..first+n-1 of a small DAG-like layout: groups of 4 siblings that share their parents'
// pair and their parents list, own pairs shared by pairs of siblings, consecutive children, and a node
// whose parent lies before the run.
std::vector<NodeRecord> records(uint32_t first, uint32_t n) {
  std::vector<NodeRecord> out(n);
  for (uint32_t i = 0; i < n; ++i) {
    NodeRecord& r = out[i];
    const uint32_t id = first + i;
    r.kind = i % 7 == 6 ? NodeKind::hlod_proxy : NodeKind::cluster;
    r.encoding = i % 11 == 10 ? NodeEncoding::raw : NodeEncoding::codec;
    r.representation = (i / 9) % 2;
    r.material = (i / 5) % 2;
    r.level = 3 - std::min<uint32_t>(3, i / 4);
    r.page = i / 6 % 4;  // back to page 0 after page 3: pages need not increase
    r.offset = (i % 6) * 100 + (i % 3 == 0 ? 7 : 0);
    r.size = 90 + i;
    r.triangles = 120 + i;
    r.error = 0.5f + float(i / 2) * 0.125f;
    r.sphere = {{float(i / 2), -1.5f, 2.0f}, 3.0f + float(i / 2)};
    if (i % 4 == 3 && i + 4 < n) r.children = {id + 4, id + 5, id + 6};
    if (i >= 4) {
      const uint32_t p = first + (i / 4) * 4 - 1;  // the previous group's last record (or one before the run)
      r.parents = {p, p > 0 ? p - 1 : p + 1};
      r.parent_error = 9.0f + float(i / 4);
      r.parent_sphere = {{0.25f, float(i / 4), 0.0f}, 50.0f};
    }
    if (r.kind == NodeKind::hlod_proxy) r.objects = {2, 0};
  }
  return out;
}

void expect_same(const std::vector<NodeRecord>& a, const std::vector<NodeRecord>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("record " + std::to_string(i));
    EXPECT_EQ(a[i].kind, b[i].kind);
    EXPECT_EQ(a[i].encoding, b[i].encoding);
    EXPECT_EQ(a[i].representation, b[i].representation);
    EXPECT_EQ(a[i].material, b[i].material);
    EXPECT_EQ(a[i].level, b[i].level);
    EXPECT_EQ(a[i].page, b[i].page);
    EXPECT_EQ(a[i].offset, b[i].offset);
    EXPECT_EQ(a[i].size, b[i].size);
    EXPECT_EQ(a[i].cluster, b[i].cluster);
    EXPECT_EQ(a[i].triangles, b[i].triangles);
    EXPECT_EQ(a[i].error, b[i].error);
    EXPECT_EQ(a[i].sphere.center, b[i].sphere.center);
    EXPECT_EQ(a[i].sphere.radius, b[i].sphere.radius);
    EXPECT_EQ(a[i].parent_error, b[i].parent_error);
    EXPECT_EQ(a[i].parent_sphere.center, b[i].parent_sphere.center);
    EXPECT_EQ(a[i].parent_sphere.radius, b[i].parent_sphere.radius);
    EXPECT_EQ(a[i].children, b[i].children);
    EXPECT_EQ(a[i].parents, b[i].parents);
    EXPECT_EQ(a[i].objects, b[i].objects);
  }
}

TEST(IndexRecords, ARunRoundTripsExactly) {
  const RootIndex root = tables();
  for (uint32_t first : {0u, 5u, 30u}) {
    const std::vector<NodeRecord> in = records(first, 24);
    const std::vector<uint8_t> raw = serialize_nodes(in, first);
    expect_same(parse_nodes(raw, root, first, 24, "run"), in);
  }
}

TEST(IndexRecords, AParentsPairTakenFromAParentInTheRunStaysExact) {
  // Node 1's parents' pair is node 0's own pair: stored as a reference to record 0.
  std::vector<NodeRecord> in = records(0, 2);
  in[0].children = {1};
  in[1].parents = {0};
  in[1].parent_error = in[0].error;
  in[1].parent_sphere = in[0].sphere;
  const RootIndex root = tables();
  expect_same(parse_nodes(serialize_nodes(in, 0), root, 0, 2, "run"), in);
  // -0.0 equals 0.0 but is another float: it must come back as stored, not as the parent's.
  in[0].sphere.center.x = 0.0f;
  in[1].parent_sphere.center.x = -0.0f;
  const std::vector<NodeRecord> out = parse_nodes(serialize_nodes(in, 0), root, 0, 2, "run");
  EXPECT_TRUE(std::signbit(out[1].parent_sphere.center.x));
  EXPECT_FALSE(std::signbit(out[0].sphere.center.x));
}

TEST(IndexRecords, SharedPairsAreStoredOnce) {
  // 16 records with one own pair and one parents' pair between them take fewer bytes than 2 distinct pairs
  // (20 bytes each) per record would.
  std::vector<NodeRecord> in = records(0, 16);
  for (NodeRecord& r : in) {
    r.error = 1.0f, r.sphere = {{1.0f, 2.0f, 3.0f}, 4.0f};
    r.parents = {40};
    r.parent_error = 2.0f, r.parent_sphere = {{1.0f, 2.0f, 3.0f}, 8.0f};
  }
  const std::vector<uint8_t> raw = serialize_nodes(in, 0);
  EXPECT_LT(raw.size(), 2 * 20 + 16 * 16u);
  expect_same(parse_nodes(raw, tables(), 0, 16, "run"), in);
}

TEST(IndexRecords, TheClustersOfARecordShareItsBytesAndStoreThemOnce) {
  std::vector<NodeRecord> in = records(0, 12);
  const size_t alone = serialize_nodes(in, 0).size();
  // Records 1-3 are clusters 1-3 of record 0's bytes, record 7 is cluster 5 of record 6's (not stored as
  // "the next cluster": record 6 is its cluster 0), record 9 is cluster 30 (the last possible) of its own.
  for (uint32_t i = 1; i <= 3; ++i) {
    in[i].page = in[0].page, in[i].offset = in[0].offset, in[i].size = in[0].size, in[i].cluster = i;
  }
  in[7].page = in[6].page, in[7].offset = in[6].offset, in[7].size = in[6].size, in[7].cluster = 5;
  in[9].cluster = kMaxRecordClusters - 1;
  const std::vector<uint8_t> raw = serialize_nodes(in, 0);
  EXPECT_LT(raw.size(), alone);  // clusters 1-3 store neither page, offset, size nor cluster
  expect_same(parse_nodes(raw, tables(), 0, 12, "run"), in);
}

// The bytes of field `name` (kIndexFieldNames) of the run of records `in` from id 0.
size_t field_bytes(const std::vector<NodeRecord>& in, std::string_view name) {
  const auto fields = serialize_node_fields(in, 0);
  for (size_t f = 0; f < kIndexFields; ++f)
    if (kIndexFieldNames[f] == name) return fields[f].size();
  ADD_FAILURE() << "no field " << name;
  return 0;
}

TEST(IndexRecords, ARecordStoresNoVertexCount) {
  // Record 1 repeats record 0 (the next cluster of its bytes, its links and pairs, no objects): it stores
  // head, 3 deltas, triangles, object count and 2 pair codes, 8 bytes (kMinNodeRecordBytes).
  std::vector<NodeRecord> in = records(0, 2);
  in[0].objects.clear();
  in[1] = in[0];
  in[1].cluster = in[0].cluster + 1;
  auto total = [](const std::vector<NodeRecord>& r) {
    size_t bytes = 0;
    for (const std::vector<uint8_t>& f : serialize_node_fields(r, 0)) bytes += f.size();
    return bytes;
  };
  EXPECT_EQ(total(in) - total({in[0]}), 8u);
  expect_same(parse_nodes(serialize_nodes(in, 0), tables(), 0, 2, "run"), in);
}

TEST(IndexRecords, ParentsThatListARecordAsTheirChildAreNotStored) {
  // A DAG's links: records 0 and 1 were simplified from group {2, 3, 4}, whose parents they are; 3 and 4
  // from {5, 6}. Only record 2's list would be stored were it not implied (3's and 4's equal the previous
  // record's), and 5's (6's equals 5's); record 0's is empty. Record 7's parent is record 2 though record 2
  // does not list it as a child: it is stored.
  std::vector<NodeRecord> in = records(0, 8);
  for (NodeRecord& r : in) r.children.clear(), r.parents.clear(), r.parent_error = INFINITY;
  in[0].children = in[1].children = {2, 3, 4};
  in[3].children = in[4].children = {5, 6};
  in[2].parents = in[3].parents = in[4].parents = {0, 1};
  in[5].parents = in[6].parents = {3, 4};
  in[7].parents = {2};
  for (NodeRecord& r : in)
    if (!r.parents.empty())
      r.parent_error = in[r.parents[0]].error, r.parent_sphere = in[r.parents[0]].sphere;
  EXPECT_EQ(field_bytes(in, "parents"), 1u + 2u);  // record 0's empty list (count 0) and record 7's
  expect_same(parse_nodes(serialize_nodes(in, 0), tables(), 0, 8, "run"), in);
  // Parents listed in another order than the ids' are stored.
  in[2].parents = in[3].parents = in[4].parents = {1, 0};
  EXPECT_EQ(field_bytes(in, "parents"), 1u + 3u + 2u);
  expect_same(parse_nodes(serialize_nodes(in, 0), tables(), 0, 8, "run"), in);
}

TEST(IndexRecords, AChildrenListSeenEarlierInTheRunIsAReference) {
  // Lists A = {10, 11, 12} and B = {13, 14} alternate (siblings whose records are not consecutive): A takes
  // 4 bytes (2 x 3, first id 10 past record 0's id, two zeros), B 3 (2 x 2, first right after A's end, a
  // zero), each repetition 1 (a reference).
  std::vector<NodeRecord> in = records(0, 6);
  for (size_t i = 0; i < in.size(); ++i)
    in[i].children = i % 2 ? std::vector<uint32_t>{13, 14} : std::vector<uint32_t>{10, 11, 12};
  EXPECT_EQ(field_bytes(in, "children"), 4u + 3u + 4u);
  expect_same(parse_nodes(serialize_nodes(in, 0), tables(), 0, 6, "run"), in);
}

TEST(IndexRecords, AnOwnSphereIsCodedAgainstItsParentsSphere) {
  // Siblings of two groups interleaved (as a DAG's page order leaves them), each group inside its parents'
  // sphere of radius 8 at (+-1000, +-1000, +-1000): each own centre lies within 2 units (32 grid steps of
  // 2^-4) of its parents' centre, one svarint byte a coordinate; against the previous compact pair (the
  // other group's, 2000 units away) it would take 3.
  std::vector<NodeRecord> in = records(0, 8);
  for (uint32_t i = 0; i < 8; ++i) {
    NodeRecord& r = in[i];
    const float side = i % 2 ? -1000.0f : 1000.0f;
    r.children.clear(), r.objects.clear();
    r.parents = {40u + i % 2};
    r.parent_error = 2.0f, r.parent_sphere = {{side, side, side}, 8.0f};
    r.error = 1.0f, r.sphere = {{side + 0.25f * float(i), side - 0.125f * float(i), side + 1.5f}, 4.0f};
  }
  // Two parents' pairs (3 coordinates of up to 3 bytes each), 8 own pairs of 3 bytes.
  EXPECT_LE(field_bytes(in, "sphere centres"), 2 * 9 + 8 * 3u);
  expect_same(parse_nodes(serialize_nodes(in, 0), tables(), 0, 8, "run"), in);
}

// A hand-written run's field streams, in the order of index.hpp ("Node records").
enum Field : size_t {
  kHead,
  kDeltas,
  kLocation,
  kSize,
  kTriangles,
  kChildren,
  kParents,
  kObjects,
  kPairCode,
  kPairError,
  kPairExponent,
  kPairCentre,
  kPairRadius,
  kFields
};
using Fields = std::array<ByteWriter, kFields>;
std::vector<uint8_t> run_bytes(const Fields& fields) {
  ByteWriter w;
  for (const ByteWriter& f : fields) w.varint(f.bytes.size());
  for (const ByteWriter& f : fields) w.raw(f.bytes);
  return std::move(w.bytes);
}
// A literal pair (f32 error, centre, radius).
void literal(Fields& f, float error, float radius) {
  f[kPairError].f32(error);
  for (int a = 0; a < 3; ++a) f[kPairCentre].f32(0.0f);
  f[kPairRadius].f32(radius);
}
// One record's fields but the pairs: the given head, no links, and cluster (unless head bit 5 says it is the
// previous record's next cluster).
Fields record_fields(uint8_t head, bool with_parent, uint64_t cluster = 0) {
  Fields f;
  f[kHead].u8(head);
  for (int field = 0; field < 3; ++field) f[kDeltas].svarint(0);  // representation, material, level
  if (!(head & 32))
    f[kLocation].svarint(0), f[kLocation].svarint(0), f[kSize].varint(10), f[kSize].varint(cluster);
  f[kTriangles].varint(1);
  if (!(head & 8)) f[kChildren].varint(0);  // no children
  if (!(head & 16)) {
    f[kParents].varint(with_parent ? 1 : 0);
    if (with_parent) f[kParents].svarint(-1);  // parent id 4: the record before the run
  }
  f[kObjects].varint(0);  // no objects
  return f;
}

// The hand-written run: one record with the given head, list and pair codes (parents' first).
std::vector<uint8_t> one_record(uint8_t head, uint64_t own_code, uint64_t parent_code, bool with_parent,
                                uint64_t cluster = 0) {
  Fields f = record_fields(head, with_parent, cluster);
  f[kPairCode].varint(parent_code);
  if (parent_code == 1) literal(f, INFINITY, 0.0f);
  f[kPairCode].varint(own_code);
  if (own_code == 0) literal(f, 1.0f, 1.0f);
  return run_bytes(f);
}

// Each hand-written run (one record, id 5) fails to parse with a one-line error naming the file.
void expect_one_line_errors(const std::vector<std::pair<const char*, std::vector<uint8_t>>>& cases,
                            const RootIndex& root) {
  for (const auto& [name, raw] : cases) {
    try {
      parse_nodes(raw, root, 5, 1, "hostile.lods: index page");
      ADD_FAILURE() << name << ": no error";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("hostile.lods", 0), 0u) << name << ": " << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << name;
    }
  }
}

TEST(IndexRecords, HostileReferencesAreErrors) {
  const RootIndex root = tables();
  // The hand-written record itself parses.
  EXPECT_NO_THROW(parse_nodes(one_record(0, 0, 1, false), root, 5, 1, "run"));
  const std::vector<std::pair<const char*, std::vector<uint8_t>>> cases = {
      {"own pair refers past the table", one_record(0, 3, 1, false)},
      {"parents' pair refers past the table", one_record(0, 0, 4, false)},
      {"parents' pair from a parent before the run", one_record(0, 0, 0, true)},
      {"parents' pair from a node without parents", one_record(0, 0, 0, false)},
      {"same children as a record the run does not have", one_record(8, 0, 1, false)},
      {"same parents as a record the run does not have", one_record(16, 0, 1, false)},
      {"the next cluster of a record the run does not have", one_record(32, 0, 1, false)},
      {"cluster index past the most a record holds", one_record(0, 0, 1, false, kMaxRecordClusters)},
      {"huge cluster index", one_record(0, 0, 1, false, uint64_t(1) << 40)},
      {"unknown record flag", one_record(128, 0, 1, false)},
      {"parents implied but no record of the run lists it", one_record(64, 0, 1, false)},
      {"parents both implied and the previous record's", one_record(64 | 16, 0, 1, false)},
  };
  // A children list referring to a list the run does not have, and one longer than the stream.
  for (uint64_t code : {uint64_t(1), uint64_t(2) << 40}) {
    Fields f = record_fields(0, false);
    f[kChildren] = ByteWriter();
    f[kChildren].varint(code);
    f[kPairCode].varint(1), literal(f, INFINITY, 0.0f), f[kPairCode].varint(0), literal(f, 1.0f, 1.0f);
    expect_one_line_errors({{"children list", run_bytes(f)}}, root);
  }
  expect_one_line_errors(cases, root);
}

// Records 0..n-1 whose pairs are all distinct, with centres and radii of full float precision.
std::vector<NodeRecord> distinct_pairs(uint32_t n) {
  std::vector<NodeRecord> out = records(0, n);
  for (uint32_t i = 0; i < n; ++i) {
    NodeRecord& r = out[i];
    const float f = float(i) * 0.7071067f;
    r.error = 0.01f * (1.0f + std::sqrt(f));
    r.sphere = {{std::sin(f) * 13.1f, std::cos(f) * 7.3f, 2.9f + f}, 0.37f + f * 0.013f};
    if (!r.parents.empty())
      r.parent_error = 10.0f + std::sqrt(f), r.parent_sphere = {r.sphere.center, 33.3f + f};
  }
  return out;
}

// A run whose records all repeat one long children list (a byte or none each) would expand a few KB into
// records x list length ids: the parser bounds a run's links by 64 a record plus one a byte of the run.
TEST(IndexRecords, ARunThatRepeatsALongListIsAnError) {
  RootIndex root = tables();
  root.node_count = 5000;
  auto run_listing = [](uint32_t list_length) {
    std::vector<NodeRecord> in = distinct_pairs(200);
    std::vector<uint32_t> list(list_length);
    std::iota(list.begin(), list.end(), 300u);
    for (NodeRecord& r : in) r.children = list;
    return in;
  };
  const std::vector<NodeRecord> modest = run_listing(40);  // 8,000 links: under 64 x 200
  expect_same(parse_nodes(serialize_nodes(modest, 0), root, 0, 200, "run"), modest);
  const std::vector<uint8_t> amplified = serialize_nodes(run_listing(1000), 0);
  EXPECT_LT(amplified.size(), 20000u);  // 200,000 links from under 20 KB
  try {
    parse_nodes(amplified, root, 0, 200, "hostile.lods: index page");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("links"), std::string::npos) << e.what();
  }
}

TEST(IndexRecords, RoundedPairsAreCompactAndComeBackBitForBit) {
  const std::vector<NodeRecord> exact = distinct_pairs(48);
  std::vector<NodeRecord> rounded = exact;
  round_pairs(rounded);
  const RootIndex root = tables();
  const std::vector<uint8_t> exact_raw = serialize_nodes(exact, 0), rounded_raw = serialize_nodes(rounded, 0);
  expect_same(parse_nodes(exact_raw, root, 0, 48, "run"), exact);
  expect_same(parse_nodes(rounded_raw, root, 0, 48, "run"), rounded);
  // 96 distinct pairs: 20 bytes each as literals, at most 12 compact (3 error, 1 exponent, 3 x 2 centre, 2
  // radius), so at least 8 x 96 bytes fewer.
  EXPECT_LE(rounded_raw.size() + 8 * 96, exact_raw.size());
}

TEST(IndexRecords, EveryKindOfFloatComesBackBitForBit) {
  // Values the compact form holds (zeros, powers of two, subnormals, far apart exponents) and values it does
  // not (-0, an error with low bits set, a negative radius's sign), in one run: each pair back bit for bit.
  const float values[] = {0.0f,   -0.0f, 1.0f, -3.5f,           1e-40f, 0x1p-126f, 0x1p100f,
                          -1e30f, 7.25f, 1.1f, 0x1.fffffep127f, 3e-39f, 65536.0f,  0.1f};
  const size_t n = std::size(values);
  std::vector<NodeRecord> in = records(0, uint32_t(n));
  for (size_t i = 0; i < n; ++i) {
    in[i].error = std::abs(values[(i + 3) % n]);
    in[i].sphere = {{values[i], values[(i + 1) % n], values[(i + 5) % n]}, std::abs(values[(i + 2) % n])};
    if (i == 4) in[i].error = -0.0f;
    if (!in[i].parents.empty()) in[i].parent_error = INFINITY;
  }
  const std::vector<NodeRecord> out = parse_nodes(serialize_nodes(in, 0), tables(), 0, uint32_t(n), "run");
  ASSERT_EQ(out.size(), n);
  for (size_t i = 0; i < n; ++i) {
    SCOPED_TRACE("record " + std::to_string(i));
    EXPECT_EQ(std::bit_cast<uint32_t>(out[i].error), std::bit_cast<uint32_t>(in[i].error));
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(std::bit_cast<uint32_t>(out[i].sphere.center[a]),
                std::bit_cast<uint32_t>(in[i].sphere.center[a]));
    EXPECT_EQ(std::bit_cast<uint32_t>(out[i].sphere.radius), std::bit_cast<uint32_t>(in[i].sphere.radius));
  }
}

// A compact pair: error bits (top 24), exponent delta, centre deltas, radius integer.
struct Compact {
  uint32_t error_top;
  int64_t exponent;
  std::array<int64_t, 3> centre;
  uint64_t radius;
};
// One record without parents whose own pair is compact pair `c`, its parents' pair a literal (+infinity).
std::vector<uint8_t> compact_record(const Compact& c) {
  Fields f = record_fields(0, false);
  f[kPairCode].varint(1);
  literal(f, INFINITY, 0.0f);
  f[kPairCode].varint(1);
  f[kPairError].u8(uint8_t(c.error_top)), f[kPairError].u8(uint8_t(c.error_top >> 8));
  f[kPairError].u8(uint8_t(c.error_top >> 16));
  f[kPairExponent].svarint(c.exponent);
  for (int64_t k : c.centre) f[kPairCentre].svarint(k);
  f[kPairRadius].varint(c.radius);
  return run_bytes(f);
}

TEST(IndexRecords, HostileCompactPairsAreErrors) {
  const RootIndex root = tables();
  // The hand-written compact pair parses: error 1.0 (0x3f800000), centre (1, -2, 3) x 2^-1, radius 5 x 2^-1.
  const std::vector<NodeRecord> ok =
      parse_nodes(compact_record(Compact{0x3f8000, -1, {1, -2, 3}, 5}), root, 5, 1, "run");
  EXPECT_EQ(ok[0].error, 1.0f);
  EXPECT_EQ(ok[0].sphere.center, glm::vec3(0.5f, -1.0f, 1.5f));
  EXPECT_EQ(ok[0].sphere.radius, 2.5f);
  std::vector<std::pair<const char*, std::vector<uint8_t>>> cases = {
      {"NaN error", compact_record(Compact{0x7fc000, 0, {0, 0, 0}, 1})},
      {"negative error", compact_record(Compact{0xbf8000, 0, {0, 0, 0}, 1})},
      {"exponent far below the float range", compact_record(Compact{0x3f8000, -100000, {0, 0, 0}, 1})},
      {"exponent far above the float range",
       compact_record(Compact{0x3f8000, int64_t(1) << 40, {0, 0, 0}, 1})},
      {"centre beyond the float range", compact_record(Compact{0x3f8000, 120, {int64_t(1) << 30, 0, 0}, 1})},
      {"centre integer past the limit", compact_record(Compact{0x3f8000, 0, {0, INT64_MAX, 0}, 1})},
      {"centre integer below the limit", compact_record(Compact{0x3f8000, 0, {0, 0, INT64_MIN}, 1})},
      {"radius integer past the limit", compact_record(Compact{0x3f8000, 0, {0, 0, 0}, UINT64_MAX})},
      {"radius beyond the float range", compact_record(Compact{0x3f8000, 127, {0, 0, 0}, 4})},
  };
  std::vector<uint8_t> truncated = compact_record(Compact{0x3f8000, -1, {1, -2, 3}, 5});
  truncated.pop_back();  // the last stream (sphere radii) one byte short
  cases.push_back({"truncated compact pair", truncated});
  std::vector<uint8_t> long_stream = compact_record(Compact{0x3f8000, -1, {1, -2, 3}, 5});
  long_stream[0] = 0x7f;  // the first stream claims more bytes than the run holds
  cases.push_back({"field stream past the run", long_stream});
  std::vector<uint8_t> trailing = compact_record(Compact{0x3f8000, -1, {1, -2, 3}, 5});
  trailing[kPairRadius] += 1, trailing.push_back(0);  // a byte no record reads
  cases.push_back({"trailing byte in a field stream", trailing});
  expect_one_line_errors(cases, root);
}

}  // namespace
}  // namespace lodstream::test
