// The node codec: turns one node's geometry (a chunk of a lodstream::Mesh, at most 65536 vertices) into bytes
// and back. Everything else in the package treats a node's bytes as opaque and reaches the codec only through
// this interface, so a better codec replaces this one by adding a class and an id (the root index records
// which codec wrote the package).
//
// Positions live on a per-representation integer grid (PositionGrid): q = round((p - origin) / step), decoded
// as origin + q * step. A node may spend fewer bits (position_shift k: free vertices are rounded to multiples
// of 2^k grid steps), EXCEPT vertices flagged `locked`, which always decode to the exact finest-grid value.
// Because the grid is shared by every node of a representation and the decode is one deterministic formula, a
// vertex that two nodes store as locked (or with the same shift) decodes bit-identically in both: that keeps
// cuts crack-free. See quantized_node.hpp for how the remaining precision is spent. The codecs: MeshoptCodec
// (id 1, the default), PredictiveCodec (id 2) and TraversalCodec (id 3).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/mesh.hpp"

namespace lodstream::package {

// std::round (halves away from zero) of an x with |x| < 2^62, inline: the baseline x86-64 target has no
// rounding instruction, so std::round and std::llround are libm calls (~30 instructions with the call, 4 M
// calls in an elephant_1m bake's quantization). x - trunc(x) is exact for every double (below 2^52 both are
// representable, above it x is an integer), so comparing it with 1/2 rounds as std::round does.
inline int64_t round_half_away(double x) {
  const int64_t t = int64_t(x);  // toward zero
  const double fraction = x - double(t);
  return t + (fraction >= 0.5) - (fraction <= -0.5);
}

// The quantization grid of one representation (object space). step is the finest step.
struct PositionGrid {
  glm::vec3 origin{0.0f};
  float step = 1.0f;

  // The grid with origin at the box minimum and step = diagonal * 2^-bits (bits = 14 gives the ≤ 2^-14 of the
  // diagonal that DESIGN.md requires of the finest level; the error per axis is at most step / 2). Bits need
  // not be whole: the step is any float.
  static PositionGrid for_bounds(const Bounds& bounds, double bits = 14);

  // The grid for_bounds(mesh.bounds(), b) with the fewest bits b in [min_bits, max_bits], to 1/8 of a bit
  // above min_bits, on which the mesh's distinct positions stay distinct (no two of them round to one grid
  // point), or max_bits when none is.
  // Used with snap(): e.g. buildings.obj tessellates footprints with vertices 0.013 apart, under the 2^-14
  // step (0.017) of its 279-unit diagonal, and also holds near-duplicate vertices 1e-5 apart (float noise,
  // which no grid separates): it gets max_bits, and the 92 near-duplicates that still collide there are
  // welded by snap(). Only the finest level pays for the extra bits: coarser nodes drop low bits in
  // proportion to their error (the bake's position_shift). Requires max_bits <= 20. Cost: O(V) per bit count
  // tried (whole bits up to the first that separates, then three halvings), on every core; 32 bytes per
  // vertex of scratch.
  static PositionGrid separating(const Mesh& mesh, int min_bits = 14, int max_bits = 20);
  // Moves every position to the grid point the codec decodes it to and drops the triangles this makes
  // degenerate (two corners on one grid point). A hierarchy built on the snapped mesh has a finest level
  // that decodes to exactly the surface it was built from, so distinct vertices never merge at decoding into
  // slivers that the hierarchy did not see (which made buildings.obj fail the crack test of inspect
  // --verify). Moves positions by at most sqrt(3)/2 step. Requires positions less than 2^62 steps from the
  // origin (round_half_away), as every mesh within the bounds of a for_bounds grid is. Cost: O(V + T).
  void snap(Mesh& mesh) const;
  // log2(diagonal / step), rounded: the bits a grid spends per diagonal (what for_bounds was given).
  int bits(const Bounds& bounds) const;
};

// One node's geometry as the caller hands it to a codec.
struct NodeGeometry {
  const Mesh* mesh = nullptr;  // positions required; normals, uvs, colors optional; material is not stored
  // Per vertex, nonzero = locked: decoded exactly on the finest grid whatever the shift. Empty = none locked.
  // Flag every vertex that another node stores with a different position_shift (group borders of a cluster
  // DAG).
  std::span<const uint8_t> locked;
  // Free vertices are rounded to multiples of 2^position_shift finest-grid steps (0 = finest). A coarse node
  // whose error is e may use a shift with 2^k * step well below e.
  uint32_t position_shift = 0;
  // Octahedral normal precision, bits per component (4..16).
  uint32_t normal_bits = 10;
  // Progressive-mesh chunks: this chunk's vertex i is vertex first_vertex + i of the representation, and
  // indices may refer to any vertex below first_vertex + vertex_count (earlier chunks). With first_vertex > 0
  // or preserve_order, the codec keeps vertex and triangle order; otherwise it reorders both for compression.
  uint32_t first_vertex = 0;
  bool preserve_order = false;
  // Optional 32-bit value per vertex, stored losslessly and opaque to the codec (e.g. a collapse parent).
  std::span<const uint32_t> vertex_data;
  // Indices may refer to any vertex below index_end (0 = first_vertex + vertex count): a progressive-mesh
  // step stores its triangles' full-resolution corners, which may lie in later steps. At least first_vertex +
  // vertex count when nonzero.
  uint32_t index_end = 0;
  // Optional bytes stored losslessly after the geometry, opaque to the codec (e.g. a progressive step's
  // vertex-substitution chains, package/progressive_prefix.hpp).
  std::span<const uint8_t> extra;
  // A record of several clusters (a page group's clusters welded on their shared vertices, one vertex pool):
  // the triangle count of each cluster, adding up to the mesh's; the mesh's triangles are the clusters'
  // consecutive ranges in this order. Empty = one cluster. At most NodeCodec::max_record_clusters() entries;
  // the codec keeps each cluster's triangles a consecutive range (records.hpp extracts one).
  std::span<const uint32_t> cluster_triangles;
};

// A decoded node: `mesh.indices` number vertices as the representation does (chunk vertex i is first_vertex +
// i; for ordinary nodes first_vertex = 0 and indices < vertex_count). The same triangles with the same
// winding as encoded, possibly reordered, each possibly rotated; attributes within the quantization error.
struct DecodedNode {
  Mesh mesh;
  uint32_t first_vertex = 0;
  uint32_t index_end = 0;  // every index is below it (first_vertex + vertex count unless encoded larger)
  std::vector<uint32_t> vertex_data;
  std::vector<uint8_t> extra;
  // A record's clusters: triangle count of each (consecutive ranges of mesh.indices, in order), as encoded;
  // empty for a node of one cluster.
  std::vector<uint32_t> cluster_triangles;
};

// Bytes of each part of one encoded node (before zstd), for size reports. Every codec lays the parts out in
// this order, so they are also consecutive ranges of the node's bytes: header, vertices (positions, then
// normals, then the other attributes), locked, indices.
// Codec 1 interleaves all attributes in one vertex stream (normals = attributes = 0: measure one attribute's
// cost by encoding with and without it); codecs 2 and 3 store normal residuals and the other attributes
// (UVs, colours, vertex_data) apart and count them in `normals` and `attributes`, which are part of
// `vertices`.
struct NodeSizeBreakdown {
  size_t header = 0, vertices = 0, locked = 0, indices = 0;
  size_t normals = 0, attributes = 0;  // of `vertices`
  // Of positions() and normals: their first bytes, the low byte planes where the codec stores byte planes
  // (codecs 2 and 3: one byte per vertex and component), 0 otherwise.
  size_t position_low = 0, normal_low = 0;
  // Of indices: its last bytes, a stream that a page stores apart (page_parts.hpp; codec 3: the traversal's
  // references), 0 for none.
  size_t tail = 0;
  // The vertices the node stores (its header's count: a record's shared vertex pool).
  uint32_t stored_vertices = 0;
  size_t total() const { return header + vertices + locked + indices; }
  size_t positions() const { return vertices - normals - attributes; }
};

class NodeCodec {
 public:
  virtual ~NodeCodec() = default;
  // The id recorded in the package; unique per codec and per incompatible revision of its byte format.
  virtual uint32_t id() const = 0;
  // The most clusters one encoded record may hold (NodeGeometry::cluster_triangles): 1 for a codec that
  // stores one cluster per node (codecs 1 and 2, which reorder triangles freely).
  virtual uint32_t max_record_clusters() const { return 1; }
  // Encodes; throws lodstream::Error on invalid input (sizes, > 65536 vertices, indices out of range,
  // positions off the grid's range). Thread-safe: callers may encode many nodes in parallel.
  virtual std::vector<uint8_t> encode(const NodeGeometry& geometry, const PositionGrid& grid) const = 0;
  // Decodes bytes from any source: every size, count and index is checked, so a corrupted node gives a
  // lodstream::Error starting with `where`, never a crash or an allocation larger than a small multiple of
  // bytes.size() + 65536 vertices. Thread-safe.
  virtual DecodedNode decode(std::span<const uint8_t> bytes, const PositionGrid& grid,
                             const std::string& where) const = 0;
  // decode() into `out`, every field of which it overwrites, reusing out's buffers: a caller that decodes
  // many nodes into one DecodedNode allocates them once, and clears only what outgrows them. This default
  // moves decode()'s result in. Thread-safe as decode.
  virtual void decode_into(std::span<const uint8_t> bytes, const PositionGrid& grid, const std::string& where,
                           DecodedNode& out) const {
    out = decode(bytes, grid, where);
  }
  // Where the bytes of an encoded node of `node_size` bytes go, from its first bytes (`bytes` holds at least
  // its header and may end before or run past the node's end: only the header is read). Lets a page stored
  // by part (page_parts.hpp) find each node's parts from the headers alone. Throws like decode, also when the
  // parts do not add up to node_size. Cost: O(1).
  virtual NodeSizeBreakdown layout(std::span<const uint8_t> bytes, size_t node_size,
                                   const std::string& where) const = 0;
  // layout() of a whole node.
  NodeSizeBreakdown breakdown(std::span<const uint8_t> bytes, const std::string& where) const {
    return layout(bytes, bytes.size(), where);
  }
};

// The codec that new packages are written with.
const NodeCodec& default_node_codec();
// The codec a package names; throws lodstream::Error for an unknown id.
const NodeCodec& node_codec(uint32_t id);

}  // namespace lodstream::package
