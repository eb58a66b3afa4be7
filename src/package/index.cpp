#include "package/index.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/format.hpp"
#include "package/quantized_node.hpp"

namespace lodstream::package {

namespace {

// Smallest serialized node record (index.hpp, "Node records"): head, 3 field deltas, triangles, vertices, the
// object count and the two pair codes, with both link lists implied and page, offset, size and cluster
// those of the previous record's bytes (bit 5).
constexpr size_t kMinNodeRecordBytes = 9;

void write_sphere(ByteWriter& w, const Sphere& s) {
  w.f32(s.center.x), w.f32(s.center.y), w.f32(s.center.z), w.f32(s.radius);
}
Sphere read_sphere(ByteReader& r) {
  Sphere s;
  for (int a = 0; a < 3; ++a) s.center[a] = r.finite_f32("sphere centre");
  s.radius = r.finite_f32("sphere radius");
  if (s.radius < 0.0f) r.fail("negative sphere radius");
  return s;
}
// An error bound: non-negative, +infinity allowed (nothing replaces the node), NaN rejected.
float read_error(ByteReader& r) {
  float e = r.f32();
  if (std::isnan(e) || e < 0.0f) r.fail("invalid error bound");
  return e;
}

void write_range(ByteWriter& w, const Range& range) {
  w.u64(range.offset), w.u32(range.size), w.u32(range.raw_size), w.u64(range.checksum);
}
Range read_range(ByteReader& r, uint32_t max_raw, const char* what) {
  Range range;
  range.offset = r.u64(), range.size = r.u32(), range.raw_size = r.u32(), range.checksum = r.u64();
  if (range.raw_size > max_raw)
    r.fail(std::string(what) + " raw size " + std::to_string(range.raw_size) + " exceeds the limit");
  return range;
}

// A list of node ids (index.hpp, "Node records"): varint count, then each id as an svarint delta from the
// previous one plus 1 (the first from `base`), so that runs of consecutive ids are runs of zero bytes.
void write_ids(ByteWriter& w, const std::vector<uint32_t>& ids, uint32_t base) {
  w.varint(ids.size());
  int64_t previous = int64_t(base) - 1;
  for (uint32_t id : ids) w.svarint(int64_t(id) - previous - 1), previous = id;
}
std::vector<uint32_t> read_ids(ByteReader& r, uint32_t base, uint64_t limit, const char* what) {
  std::vector<uint32_t> ids(r.count(1, what));
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

// What a run of node records (the root index's, or one index page's) is coded against: its records so far
// and the distinct pairs they stored, in order of first appearance. Cost: O(distinct pairs) per pair coded.
struct RecordRun {
  uint32_t first_id = 0;
  std::span<const NodeRecord> done;  // records first_id .. first_id + done.size() - 1
  std::vector<ErrorPair> pairs;

  const NodeRecord& previous() const {
    static const NodeRecord none;  // every field 0
    return done.empty() ? none : done.back();
  }
  // The parents' pair can be taken from parents[0] when that record is already in this run.
  const NodeRecord* first_parent(const NodeRecord& n) const {
    if (n.parents.empty() || n.parents[0] < first_id || n.parents[0] - first_id >= done.size())
      return nullptr;
    return &done[n.parents[0] - first_id];
  }
  // Pair code: 0 = a literal (error f32, sphere 4 f32) that joins the table, k >= 1 = the k-th latest pair of
  // the table; `skip` codes below it are taken by the caller.
  void write_pair(ByteWriter& w, const ErrorPair& p, uint64_t skip) {
    const auto it = std::find(pairs.rbegin(), pairs.rend(), p);
    if (it != pairs.rend()) {
      w.varint(skip + 1 + uint64_t(it - pairs.rbegin()));
      return;
    }
    w.varint(skip);
    w.f32(p.error);
    write_sphere(w, p.sphere);
    pairs.push_back(p);
  }
  ErrorPair read_pair(ByteReader& r, uint64_t code) {
    if (code > 0) {
      if (code > pairs.size()) r.fail("error pair reference out of range");
      return pairs[pairs.size() - code];
    }
    ErrorPair p;
    p.error = read_error(r);
    p.sphere = read_sphere(r);
    pairs.push_back(p);
    return p;
  }
};

enum : uint8_t { kSameChildren = 8, kSameParents = 16, kSameRecord = 32 };

void write_node(ByteWriter& w, const NodeRecord& n, uint32_t id, RecordRun& run) {
  const NodeRecord& prev = run.previous();
  const bool same_children = !run.done.empty() && n.children == prev.children;
  const bool same_parents = !run.done.empty() && n.parents == prev.parents;
  const bool same_record = !run.done.empty() && n.page == prev.page && n.offset == prev.offset &&
                           n.size == prev.size && n.cluster == prev.cluster + 1;
  w.u8(static_cast<uint8_t>(uint8_t(n.kind) | uint8_t(n.encoding) << 2 | (same_children ? kSameChildren : 0) |
                            (same_parents ? kSameParents : 0) | (same_record ? kSameRecord : 0)));
  w.svarint(int64_t(n.representation) - prev.representation);
  w.svarint(int64_t(n.material) - prev.material);
  w.svarint(int64_t(n.level) - prev.level);
  if (!same_record) {
    w.svarint(int64_t(n.page) - prev.page);
    w.svarint(int64_t(n.offset) - (n.page == prev.page ? int64_t(prev.offset) + prev.size : 0));
    w.varint(n.size);
    w.varint(n.cluster);
  }
  w.varint(n.triangles), w.varint(n.vertices);
  if (!same_children) write_ids(w, n.children, id);
  if (!same_parents) write_ids(w, n.parents, id);
  write_ids(w, n.objects, 0);
  run.write_pair(w, own_pair(n), 0);
  const NodeRecord* parent = run.first_parent(n);
  if (parent && own_pair(*parent) == parent_pair(n)) {
    w.varint(0);
  } else {
    run.write_pair(w, parent_pair(n), 1);
  }
}

NodeRecord read_node(ByteReader& r, const RootIndex& root, uint32_t id, RecordRun& run) {
  const NodeRecord& prev = run.previous();
  NodeRecord n;
  const uint8_t head = r.u8();
  if (head & ~uint8_t(3 | 4 | kSameChildren | kSameParents | kSameRecord))
    r.fail("node " + std::to_string(id) + ": unknown record flags");
  n.kind = NodeKind(head & 3), n.encoding = NodeEncoding((head >> 2) & 1);
  if ((head & (kSameChildren | kSameParents | kSameRecord)) && run.done.empty())
    r.fail("node " + std::to_string(id) + ": refers to a previous record that this run does not have");
  n.representation = read_delta(r, prev.representation, root.scene.representations.size(), "representation");
  n.material = read_delta(r, prev.material, root.scene.materials.size(), "material");
  n.level = read_delta(r, prev.level, 1u << 16, "level");
  if (head & kSameRecord) {
    n.page = prev.page, n.offset = prev.offset, n.size = prev.size, n.cluster = prev.cluster + 1;
  } else {
    n.page = read_delta(r, prev.page, root.pages.size(), "page");
    const int64_t base = n.page == prev.page ? int64_t(prev.offset) + prev.size : 0;
    const int64_t delta = r.svarint();  // checked before adding so that nothing overflows
    const int64_t offset = delta < -base || delta > int64_t(UINT32_MAX) ? -1 : base + delta;
    const uint64_t size = r.varint();
    if (offset < 0 || uint64_t(offset) > root.pages[n.page].raw_size ||
        size > root.pages[n.page].raw_size - uint64_t(offset)) {
      r.fail("node " + std::to_string(id) + ": bytes [" + std::to_string(offset) + ", +" +
             std::to_string(size) + ") outside page " + std::to_string(n.page));
    }
    n.offset = uint32_t(offset), n.size = uint32_t(size);
    const uint64_t cluster = r.varint();
    n.cluster = uint32_t(std::min<uint64_t>(cluster, kMaxRecordClusters));
  }
  if (n.cluster >= kMaxRecordClusters)
    r.fail("node " + std::to_string(id) + ": cluster index of its record out of range");
  n.triangles = r.index(uint64_t(UINT32_MAX) + 1, "triangle count");
  n.vertices = r.index(uint64_t(UINT32_MAX) + 1, "vertex count");
  n.children = head & kSameChildren ? prev.children : read_ids(r, id, root.node_count, "child");
  n.parents = head & kSameParents ? prev.parents : read_ids(r, id, root.node_count, "parent");
  n.objects = read_ids(r, 0, root.scene.objects.size(), "object");
  const ErrorPair own = run.read_pair(r, r.varint());
  n.error = own.error, n.sphere = own.sphere;
  const uint64_t code = r.varint();
  ErrorPair parents;
  if (code == 0) {
    const NodeRecord* parent = run.first_parent(n);
    if (!parent) r.fail("node " + std::to_string(id) + ": parents' pair refers to a record outside this run");
    parents = own_pair(*parent);
  } else {
    parents = run.read_pair(r, code - 1);
  }
  n.parent_error = parents.error, n.parent_sphere = parents.sphere;
  return n;
}

// The records of ids first_id.., coded as one run.
void write_nodes(ByteWriter& w, std::span<const NodeRecord> nodes, uint32_t first_id) {
  RecordRun run;
  run.first_id = first_id;
  for (size_t i = 0; i < nodes.size(); ++i) {
    run.done = nodes.first(i);
    write_node(w, nodes[i], first_id + uint32_t(i), run);
  }
}
std::vector<NodeRecord> read_nodes(ByteReader& r, const RootIndex& root, uint32_t first_id, size_t count) {
  std::vector<NodeRecord> nodes;  // grown as records parse (no reserve: a hostile count allocates nothing)
  RecordRun run;
  run.first_id = first_id;
  for (uint32_t i = 0; i < count; ++i) {
    run.done = nodes;
    nodes.push_back(read_node(r, root, first_id + i, run));
  }
  return nodes;
}

}  // namespace

std::vector<uint8_t> serialize_root(const RootIndex& root) {
  ByteWriter w;
  w.u32(root.codec);
  w.u32(root.node_count);
  w.u64(root.scene.input_triangles);
  w.string(root.scene.metadata);
  w.varint(root.pages.size());
  for (const Range& p : root.pages) write_range(w, p);
  w.varint(root.blobs.size());
  for (const Range& b : root.blobs) write_range(w, b);
  w.varint(root.scene.materials.size());
  for (const PackageMaterial& m : root.scene.materials) {
    w.string(m.material.name);
    for (int a = 0; a < 4; ++a) w.f32(m.material.base_color[a]);
    w.string(m.material.base_color_texture);
    w.varint(m.texture_blob == kNone ? 0 : uint64_t(m.texture_blob) + 1);
  }
  w.varint(root.scene.representations.size());
  for (const Representation& rep : root.scene.representations) {
    w.u8(static_cast<uint8_t>(rep.kind));
    w.string(rep.name);
    for (int a = 0; a < 3; ++a) w.f32(rep.bounds.min[a]);
    for (int a = 0; a < 3; ++a) w.f32(rep.bounds.max[a]);
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
  w.varint(root.index_pages.size());
  for (const IndexPage& p : root.index_pages) {
    write_range(w, p.range);
    w.varint(p.first_node), w.varint(p.node_count);
  }
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
  root.pages.resize(r.count(24, "page"));
  for (Range& p : root.pages) p = read_range(r, kMaxPageRawBytes, "page");
  root.blobs.resize(r.count(24, "blob"));
  for (Range& b : root.blobs) b = read_range(r, UINT32_MAX, "blob");
  root.scene.materials.resize(r.count(19, "material"));
  for (PackageMaterial& m : root.scene.materials) {
    m.material.name = r.string("material name");
    for (int a = 0; a < 4; ++a) m.material.base_color[a] = r.finite_f32("base colour");
    m.material.base_color_texture = r.string("texture path");
    uint32_t blob = r.index(root.blobs.size() + 1, "texture blob");
    m.texture_blob = blob == 0 ? kNone : blob - 1;
  }
  root.scene.representations.resize(r.count(44, "representation"));
  for (Representation& rep : root.scene.representations) {
    uint8_t kind = r.u8();
    if (kind > uint8_t(RepresentationKind::imposter_set)) r.fail("unknown representation kind");
    rep.kind = RepresentationKind(kind);
    rep.name = r.string("representation name");
    for (int a = 0; a < 3; ++a) rep.bounds.min[a] = r.finite_f32("bounds");
    for (int a = 0; a < 3; ++a) rep.bounds.max[a] = r.finite_f32("bounds");
    for (int a = 0; a < 3; ++a) rep.grid.origin[a] = r.finite_f32("grid origin");
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
  root.index_pages.resize(r.count(26, "index page"));
  for (IndexPage& p : root.index_pages) {
    p.range = read_range(r, kMaxIndexPageRawBytes, "index page");
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
  root.root_nodes = read_nodes(r, root, 0, root_nodes);
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
  std::vector<NodeRecord> nodes = read_nodes(r, root, first_id, count);
  r.expect_end();
  return nodes;
}

}  // namespace lodstream::package
