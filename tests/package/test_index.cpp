// Node records of the index (index.hpp, "Node records"): a run round-trips exactly, shared (error, sphere)
// pairs are stored once per run, and hostile references (to pairs or records the run does not have) are
// one-line errors.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/index.hpp"
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
    r.triangles = 120 + i, r.vertices = 70 + 2 * i;
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
    EXPECT_EQ(a[i].vertices, b[i].vertices);
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

// The hand-written run: one record with the given head, list and pair codes (and cluster, unless head bit 5
// says it is the previous record's next cluster).
std::vector<uint8_t> one_record(uint8_t head, uint64_t own_code, uint64_t parent_code, bool with_parent,
                                uint64_t cluster = 0) {
  ByteWriter w;
  w.u8(head);
  for (int field = 0; field < 3; ++field) w.svarint(0);  // representation, material, level
  if (!(head & 32)) w.svarint(0), w.svarint(0), w.varint(10), w.varint(cluster);  // page, offset, size
  w.varint(1), w.varint(3);                                                       // triangles, vertices
  if (!(head & 8)) w.varint(0);                                                   // no children
  if (!(head & 16)) {
    w.varint(with_parent ? 1 : 0);
    if (with_parent) w.svarint(-1);  // parent id 4: the record before the run
  }
  w.varint(0);  // no objects
  w.varint(own_code);
  if (own_code == 0) w.f32(1.0f), w.f32(0.0f), w.f32(0.0f), w.f32(0.0f), w.f32(1.0f);
  w.varint(parent_code);
  if (parent_code == 1) w.f32(INFINITY), w.f32(0.0f), w.f32(0.0f), w.f32(0.0f), w.f32(0.0f);
  return std::move(w.bytes);
}

TEST(IndexRecords, HostileReferencesAreErrors) {
  const RootIndex root = tables();
  // The hand-written record itself parses.
  EXPECT_NO_THROW(parse_nodes(one_record(0, 0, 1, false), root, 5, 1, "run"));
  const std::vector<std::pair<const char*, std::vector<uint8_t>>> cases = {
      {"own pair refers past the table", one_record(0, 1, 1, false)},
      {"parents' pair refers past the table", one_record(0, 0, 3, false)},
      {"parents' pair from a parent before the run", one_record(0, 0, 0, true)},
      {"parents' pair from a node without parents", one_record(0, 0, 0, false)},
      {"same children as a record the run does not have", one_record(8, 0, 1, false)},
      {"same parents as a record the run does not have", one_record(16, 0, 1, false)},
      {"the next cluster of a record the run does not have", one_record(32, 0, 1, false)},
      {"cluster index past the most a record holds", one_record(0, 0, 1, false, kMaxRecordClusters)},
      {"huge cluster index", one_record(0, 0, 1, false, uint64_t(1) << 40)},
      {"unknown record flag", one_record(64, 0, 1, false)},
  };
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

}  // namespace
}  // namespace lodstream::test
