#include "package/index.hpp"

#include <cmath>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/format.hpp"

namespace lodstream::package {

namespace {

// Smallest serialized node record: kind and encoding, 8 one-byte varints, 10 floats, 3 empty lists.
constexpr size_t kMinNodeRecordBytes = 2 + 8 + 40 + 3;

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

void write_ids(ByteWriter& w, const std::vector<uint32_t>& ids, uint32_t self) {
  w.varint(ids.size());
  for (uint32_t id : ids) w.svarint(int64_t(id) - int64_t(self));
}
std::vector<uint32_t> read_ids(ByteReader& r, uint32_t self, uint64_t limit, const char* what) {
  std::vector<uint32_t> ids(r.count(1, what));
  for (uint32_t& id : ids) {
    const int64_t delta = r.svarint();  // id - self; checked before adding so that nothing overflows
    if (delta < -int64_t(self) || delta >= int64_t(limit) - int64_t(self)) {
      r.fail(std::string(what) + " id " + std::to_string(self) + " + (" + std::to_string(delta) +
             ") out of range (" + std::to_string(limit) + ")");
    }
    id = static_cast<uint32_t>(int64_t(self) + delta);
  }
  return ids;
}

void write_node(ByteWriter& w, const NodeRecord& n, uint32_t id) {
  w.u8(static_cast<uint8_t>(n.kind));
  w.u8(static_cast<uint8_t>(n.encoding));
  w.varint(n.representation), w.varint(n.material), w.varint(n.level);
  w.varint(n.page), w.varint(n.offset), w.varint(n.size);
  w.varint(n.triangles), w.varint(n.vertices);
  w.f32(n.error);
  write_sphere(w, n.sphere);
  w.f32(n.parent_error);
  write_sphere(w, n.parent_sphere);
  write_ids(w, n.children, id);
  write_ids(w, n.parents, id);
  w.varint(n.objects.size());
  for (uint32_t o : n.objects) w.varint(o);
}

NodeRecord read_node(ByteReader& r, const RootIndex& root, uint32_t id) {
  NodeRecord n;
  uint8_t kind = r.u8(), encoding = r.u8();
  if (kind > uint8_t(NodeKind::imposter)) r.fail("node " + std::to_string(id) + ": unknown kind");
  if (encoding > uint8_t(NodeEncoding::raw)) r.fail("node " + std::to_string(id) + ": unknown encoding");
  n.kind = NodeKind(kind), n.encoding = NodeEncoding(encoding);
  n.representation = r.index(root.scene.representations.size(), "representation");
  n.material = r.index(root.scene.materials.size(), "material");
  n.level = r.index(1u << 16, "level");
  n.page = r.index(root.pages.size(), "page");
  uint64_t offset = r.varint(), size = r.varint();
  if (offset > root.pages[n.page].raw_size || size > root.pages[n.page].raw_size - offset) {
    r.fail("node " + std::to_string(id) + ": bytes [" + std::to_string(offset) + ", +" +
           std::to_string(size) + ") outside page " + std::to_string(n.page));
  }
  n.offset = uint32_t(offset), n.size = uint32_t(size);
  n.triangles = r.index(uint64_t(UINT32_MAX) + 1, "triangle count");
  n.vertices = r.index(uint64_t(UINT32_MAX) + 1, "vertex count");
  n.error = read_error(r);
  n.sphere = read_sphere(r);
  n.parent_error = read_error(r);
  n.parent_sphere = read_sphere(r);
  n.children = read_ids(r, id, root.node_count, "child");
  n.parents = read_ids(r, id, root.node_count, "parent");
  n.objects.resize(r.count(1, "object"));
  for (uint32_t& o : n.objects) o = r.index(root.scene.objects.size(), "object");
  return n;
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
  for (uint32_t id = 0; id < root.root_nodes.size(); ++id) write_node(w, root.root_nodes[id], id);
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
  root.root_nodes.reserve(root_nodes);
  for (uint32_t id = 0; id < root_nodes; ++id) root.root_nodes.push_back(read_node(r, root, id));
  r.expect_end();
  return root;
}

std::vector<uint8_t> serialize_nodes(std::span<const NodeRecord> nodes, uint32_t first_id) {
  ByteWriter w;
  for (size_t i = 0; i < nodes.size(); ++i) write_node(w, nodes[i], first_id + uint32_t(i));
  return std::move(w.bytes);
}

std::vector<NodeRecord> parse_nodes(std::span<const uint8_t> raw, const RootIndex& root, uint32_t first_id,
                                    uint32_t count, const std::string& context) {
  ByteReader r(raw, context);
  if (count > raw.size() / kMinNodeRecordBytes) r.fail("more node records than the page can hold");
  std::vector<NodeRecord> nodes;
  nodes.reserve(count);
  for (uint32_t i = 0; i < count; ++i) nodes.push_back(read_node(r, root, first_id + i));
  r.expect_end();
  return nodes;
}

}  // namespace lodstream::package
