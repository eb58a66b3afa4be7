// The first node codec (id 1): quantization + meshoptimizer 0.18's vertex and index codecs; zstd is applied
// later, per page, by the writer.
//
// Bytes of a node:
//   u8 format (1), u8 flags (1 normals, 2 uvs, 4 colors, 8 vertex_data, 16 wide positions, 32 progressive),
//   u8 position_shift k, u8 normal_bits; varint vertex count V (≤ 65536), varint triangle count T, varint
//   first_vertex; [progressive: varint index_end, varint extra size]; svarint cmin[3]; [uvs: f32 uv_min[2],
//   f32 uv_extent[2]]; varint size of the vertex, locked and index streams; the streams; [the extra bytes].
//   (Flag 32 came with progressive meshes; packages without it read as before, so the id stays 1.)
// Vertex stream: meshopt_encodeVertexBuffer over ONE interleaved record per vertex (meshopt codes each byte
//   column on its own, so interleaving costs nothing and saves a per-stream tail): position c - cmin as u16x3
//   (u32x3 when the node spans more than 65536 coarse steps), octahedral normal s8x2 (bits ≤ 8) or s16x2, UV
//   u16x2 unorm over the node's UV box, colour RGBA8 unorm, vertex_data u32; zero padding to a multiple of 4.
// Locked stream (only when k > 0): a bit per vertex (locked or not), then the k low bits of x, y, z of each
//   locked vertex, packed LSB first.
// Index stream: meshopt_encodeIndexBuffer (format version 1) of the triangles.
//
// Quantization and how precision is spent: quantized_node.hpp; the locked stream and the decode formula:
// coarse_positions.hpp. Normals: octahedral at normal_bits per component (max angular error about
// 2^(2 - normal_bits) radians); UVs: 16 bits over the node's own UV box; colours: 8 bits.
#pragma once

#include "package/node_codec.hpp"

namespace lodstream::package {

class MeshoptCodec final : public NodeCodec {
 public:
  static constexpr uint32_t kId = 1;
  MeshoptCodec();
  uint32_t id() const override { return kId; }
  std::vector<uint8_t> encode(const NodeGeometry& geometry, const PositionGrid& grid) const override;
  DecodedNode decode(std::span<const uint8_t> bytes, const PositionGrid& grid,
                     const std::string& where) const override;
  NodeSizeBreakdown layout(std::span<const uint8_t> bytes, size_t node_size,
                           const std::string& where) const override;
};

}  // namespace lodstream::package
