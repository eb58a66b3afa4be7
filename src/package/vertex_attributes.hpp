// The per-vertex attributes besides position and normal, as every node codec stores them in a vertex record:
// UV as u16x2 unorm over the node's UV box, colour as RGBA8 unorm, vertex_data as u32 (lossless), packed in
// that order from a given byte of the record. The flag bits name which are present (normals share the set).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "package/quantized_node.hpp"

namespace lodstream::package {

constexpr uint32_t kHasNormals = 1, kHasUvs = 2, kHasColors = 4, kHasVertexData = 8;

// The attribute flags of a geometry.
uint32_t attribute_flags(const NodeGeometry& geometry);

// Byte offsets of UV, colour and vertex_data in a record whose attributes start at byte `at`; end is the byte
// after the last.
struct AttributeLayout {
  size_t uv = 0, color = 0, data = 0, end = 0;
};
AttributeLayout attribute_layout(uint32_t flags, size_t at);

// Writes caller vertex `old`'s attributes into `record`. Cost: O(1).
void put_attributes(uint8_t* record, const AttributeLayout& layout, uint32_t flags,
                    const NodeGeometry& geometry, const QuantizedNode& node, uint32_t old);
// Reads the attributes of V records (`stride` bytes apart) into out.mesh.uvs / colors and out.vertex_data,
// and clears those that `flags` lacks (out's buffers may hold a previous node's). Cost: O(V).
void get_attributes(const uint8_t* records, size_t stride, size_t vertices, const AttributeLayout& layout,
                    uint32_t flags, glm::vec2 uv_min, glm::vec2 uv_extent, DecodedNode& out);

// The attribute stream of the predictive codecs: UV, colour and vertex_data (flags permitting) of the node's
// vertices in stored order (node.order), as records starting at byte 0 padded to a multiple of 4, coded by
// meshopt_encodeVertexBuffer; empty without such attributes. Cost: O(V).
std::vector<uint8_t> encode_attribute_stream(uint32_t flags, const NodeGeometry& geometry,
                                             const QuantizedNode& node);
// Decodes such a stream of V records into out as get_attributes does (throws lodstream::Error starting with
// `where` on a corrupted stream, or a non-empty one without attributes). Cost: O(V).
void decode_attribute_stream(std::span<const uint8_t> stream, uint32_t flags, size_t vertices,
                             glm::vec2 uv_min, glm::vec2 uv_extent, DecodedNode& out,
                             const std::string& where);

}  // namespace lodstream::package
