// The package index: what a client reads before any geometry. The root index holds the scene (materials,
// representations, objects), the page / index-page / blob tables and the node records of ids [0, root_nodes);
// the other node records live in index pages of consecutive ids, fetched on demand. Serialized with varints
// and zstd-compressed; parse_* validates every count, index and float against the tables it refers to.
//
// Node records: the root index's records and each index page's are one run each, coded against the run's
// previous record (zeros before the first) so that each run decodes on its own. Each field of the records is
// its own stream, so that zstd models each field apart (elephant_1m's index pages: 16.7 B per node in format
// 4, 10.3 with compact pairs and field streams): a run is 13 varint stream sizes, then the streams, in this
// order: heads; representation, material and level deltas; page and offset; size and cluster; triangle
// counts; children; parents; objects; pair codes; pair errors; compact pairs' exponents; sphere centres;
// sphere radii. A record is: u8 head (kind in bits 0-1, encoding in bit 2, bit 3 = children and bit 4 =
// parents equal to the previous record's and not stored, bit 5 = page, offset and size the previous record's
// and cluster its next, bit 6 = parents not stored, being the records earlier in the run whose children list
// holds this id, in id order, as a DAG's are: 0.56 -> 0.13 B a record on refined_elephant); svarint deltas of
// representation, material, level and page from the previous record's; svarint offset minus the previous
// record's end when on the same page (else minus 0); varint size and triangles; the children, parents and
// objects id lists (varint count, then each id as an svarint delta from the previous id + 1, the first of a
// parents list from the record's own id, of objects from 0; a children list is varint 2k + 1 for the k-th
// latest distinct children list of the run, else 2 x count and the deltas, the first from the end of the
// run's latest such list, or the record's own id); then the parents' and the own (error, sphere) pairs, which
// siblings share: a pair is a literal (f32 error, f32 centre x y z, f32 radius) or a compact pair, either of
// which joins the run's table of distinct pairs, or a reference to the k-th latest pair of that table; the
// parents' pair may also be "the own pair of parents[0]" when that record is earlier in the run. A compact
// pair holds an error whose low 8 bits are zero (3 bytes) and a sphere whose centre and radius are integers
// times a common 2^E (svarint E, centre integers, varint radius): what the writer's rounding
// (pair_rounding.hpp) makes of every pair, in about 8 bytes instead of 20. The own pair of a node with
// parents codes E against ilogb of the parents' radius and its centre against the parents' centre (it lies
// inside the parents' sphere); any other compact pair codes both against the run's previous compact pair.
// Exact floats throughout (a pair is compact only when it decodes back bit for bit): verify compares a node's
// parents' pair with its parents' own pair bit for bit.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/scene.hpp"
#include "package/node_codec.hpp"

namespace lodstream::package {

inline constexpr uint32_t kNone = UINT32_MAX;

// What a node stands for.
enum class NodeKind : uint8_t { cluster = 0, progressive_step = 1, hlod_proxy = 2, imposter = 3 };
// How its bytes are stored: through the package's node codec, or raw caller bytes (imposter images, ...).
enum class NodeEncoding : uint8_t { codec = 0, raw = 1 };
enum class RepresentationKind : uint8_t { cluster_dag = 0, progressive_mesh = 1, hlod = 2, imposter_set = 3 };

// One node (the unit of selection). Errors are totals in object units (DESIGN.md, Data model); parent_error
// is +infinity for a node nobody replaces (a root). Links are node ids: `children` = the nodes this one was
// simplified from (the group it came from), `parents` = the nodes it was simplified into (the group that
// replaces it); `objects` = objects this node stands for (HLOD proxies), empty for a representation's own
// nodes.
struct NodeRecord {
  NodeKind kind = NodeKind::cluster;
  NodeEncoding encoding = NodeEncoding::codec;
  uint32_t representation = 0;
  uint32_t material = 0;
  uint32_t level = 0;  // 0 = finest
  // Where its bytes are: [offset, offset + size) of the decompressed page `page`, the bytes of its record
  // (node_codec.hpp, NodeGeometry::cluster_triangles: a page group's clusters stored as one node), of which
  // it is cluster `cluster` (< kMaxRecordClusters; 0 for a node stored alone). The clusters of one record
  // share page, offset and size. Filled in by the writer.
  uint32_t page = 0, offset = 0, size = 0, cluster = 0;
  // Its triangles (what a cut's triangle budget counts before any geometry arrives). Its vertex count is not
  // stored: only the decoder needs it, and the node's bytes hold it (0.73 B a record after zstd on
  // refined_elephant, 9 % of its index).
  uint32_t triangles = 0;
  float error = 0.0f;
  Sphere sphere;
  float parent_error = std::numeric_limits<float>::infinity();
  Sphere parent_sphere;
  std::vector<uint32_t> children, parents, objects;
};

struct PackageMaterial {
  Material material;  // material.base_color_texture: a path (relative to the package) when not embedded
  uint32_t texture_blob = kNone;  // the embedded image file's blob, or kNone
};

// A multiresolution representation (shared by every object that instances it).
struct Representation {
  RepresentationKind kind = RepresentationKind::cluster_dag;
  std::string name;
  Bounds bounds;      // object space
  PositionGrid grid;  // quantization grid of its nodes
  uint32_t levels = 1;
  std::vector<uint32_t> roots;  // its coarsest nodes: where traversal starts
};

struct ObjectRecord {
  std::string name;
  glm::mat4 transform{1.0f};  // object to world
  uint32_t representation = 0;
};

// A stored byte range: [offset, offset + size) of the file, XXH3-64 `checksum` of those bytes, `raw_size`
// bytes after zstd (0 for a blob, stored as is).
struct Range {
  uint64_t offset = 0;
  uint32_t size = 0;
  uint32_t raw_size = 0;
  uint64_t checksum = 0;
};

struct IndexPage {
  Range range;
  uint32_t first_node = 0, node_count = 0;
};

// The scene part of the root index, as the caller of the writer describes it.
struct PackageScene {
  uint64_t input_triangles = 0;  // of the model(s) the package was baked from
  std::string metadata;          // free text for the baker (e.g. JSON build options)
  std::vector<PackageMaterial> materials;
  std::vector<Representation> representations;
  std::vector<ObjectRecord> objects;
};

struct RootIndex {
  uint32_t codec = 0;
  PackageScene scene;
  std::vector<Range> pages;
  std::vector<Range> blobs;
  std::vector<IndexPage> index_pages;
  uint32_t node_count = 0;             // all nodes
  std::vector<NodeRecord> root_nodes;  // ids [0, root_nodes.size())
};

std::vector<uint8_t> serialize_root(const RootIndex& root);
// Parses and validates (tables, index page coverage of [root_nodes, node_count), every node record).
RootIndex parse_root(std::span<const uint8_t> raw, const std::string& context);

std::vector<uint8_t> serialize_nodes(std::span<const NodeRecord> nodes, uint32_t first_id);
// The field streams of a run of records (the header comment's order), as serialize_nodes stores them after
// their sizes: where a run's bytes go. Cost: one serialization.
inline constexpr size_t kIndexFields = 13;
inline constexpr const char* kIndexFieldNames[kIndexFields] = {
    "record heads",   "record deltas",  "record locations", "record sizes", "triangle counts",
    "children",       "parents",        "objects",          "pair codes",   "pair errors",
    "pair exponents", "sphere centres", "sphere radii"};
std::array<std::vector<uint8_t>, kIndexFields> serialize_node_fields(std::span<const NodeRecord> nodes,
                                                                     uint32_t first_id);
// Parses exactly `count` records of ids first_id.. and validates each against `root`.
std::vector<NodeRecord> parse_nodes(std::span<const uint8_t> raw, const RootIndex& root, uint32_t first_id,
                                    uint32_t count, const std::string& context);

}  // namespace lodstream::package
