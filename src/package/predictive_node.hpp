// What the two predictive codecs (predictive_codec.hpp: codec 2, traversal_codec.hpp: codec 3) share: the
// layout of a node's bytes, the parallelogram-predicted positions and the normals predicted from them.
//
// Bytes of a node:
//   the common header (node_header.hpp); u8 widths (bits 0-2: bytes per position residual wp, 1..5; bit 3:
//   the normals' prediction is smoothed (predicted_normals.hpp); bits 4-5:
//   bytes per normal residual wn, 0..3, 0 exactly without normals; bits 6-7: the damping j below, 4 - value);
//   varint sizes of the attribute, locked and connectivity streams; then the position planes (3 wp V bytes),
//   the normal planes (2 wn V bytes), the attribute stream (vertex_attributes.hpp), the locked stream
//   (coarse_positions.hpp), the connectivity stream and the tail (the rest: each codec says what).
// Positions: vertex v's coarse coordinates (quantized_node.hpp) are c[v] = P + residual[v] with P the
//   parallelogram across edge o1-o2 of the triangle o1 o2 o (Touma & Gotsman 1998, "Triangle Mesh
//   Compression", GI'98) damped toward the edge's midpoint m = (c[o1] + c[o2]) / 2: P = m + j/4 (m - c[o]),
//   in integers P = floor(((4 + j)(c[o1] + c[o2]) - 2j c[o] + 4) / 8), j in {4, 3, 2} chosen per node by the
//   encoder (j = 4 is the plain parallelogram c[o1] + c[o2] - c[o]; the simplified meshes of coarse levels
//   are irregular and predict better with j = 3 or 2: measured on elephant_1m, levels 1-10 store 3-5 % fewer
//   position bits). Predictors o1, o2, o lie below v; the codec derives them from the connectivity; a single
//   predictor x is (x, x, x) (P = x for every j), and index V stands for cmin (no predictor). The residuals
//   are zigzag-mapped, byte b of component a at plane 3b + a (byte_planes.hpp); component a is axis a's
//   residual, but in a node flagged kPlanePrediction.
// Plane prediction (kPlanePrediction, chosen per node by the encoder with j, whichever residuals take the
//   fewest bits): P lies in the plane of the gate triangle o1 o2 o, and on a smooth surface v lies near that
//   plane however far it lies from P along it (the vertices of simplified levels sit at quadric-optimal
//   points, off the parallelogram along the surface). With n = (c[o1] - c[o]) x (c[o2] - c[o]), d its
//   dominant axis (the first of the largest |n[a]|), a = d + 1 and b = d + 2 (mod 3), r = c[v] - P: the
//   components are (r[d] - offset, r[a], r[b]), offset = floor(-(n[a] r[a] + n[b] r[b]) / n[d] + 1/2), that
//   is r[d] predicted so that r lies in the plane (a lifting step: exact in integers, whatever the rounding);
//   d = 0 and offset 0 when n = 0 (single predictors). Component 0 is then the distance from the plane
//   (along d) and small, the page codes it in a stream of its own (page_parts.hpp, the split form).
//   Measured offline before building it (elephant_1m's levels >= 1, residual symbols' order-0 entropy per
//   vertex): 17.36 bits plain, 16.20 with the plane prediction in one stream, 15.08 with component 0 in a
//   stream of its own (a rotation into the plane's frame: 15.02); level 0 (Loop-subdivided, regular) 4.65
//   plain, 4.94 plane; refined_elephant's levels >= 1 22.75 / 21.87 / 21.29. Decode cost: about 70
//   instructions a plane-predicted vertex (the cross product, the dominant axis, a division). `lodstream
//   bench decode --runs 1` (callgrind, decode_node + read_page), format 8 -> 9: elephant_1m 1,221.7 ->
//   1,336.8 M (+9.4 %: the plane prediction +59 M, the residual coder +58 M as more pages' positions take
//   a coded form), refined_elephant 70.9 -> 78.2 M (+10.4 %); without the split form elephant_1m 1,282.5 M
//   (+5.0 %) for 3,709,001 B instead of 3,599,331.
// Multi-parallelogram prediction (kMultiParallelogram, codec 3 only; Cohen-Or, Cohen & Irony 2002,
//   "Multi-way geometry encoding", and Draco's "multi-parallelogram" prediction): the connectivity is decoded
//   before the positions, so the traversal can give vertex v a second parallelogram (x, y, p) across another
//   edge whose two triangles it joins, every corner below v (traversal_connectivity.hpp, Parallelograms;
//   without one, v takes the single parallelogram above). P is then the average of the two damped
//   parallelograms, in integers floor((sum over both of (4 + j)(c[x] + c[y]) - 2j c[p]) + 8) / 16), and the
//   plane prediction's normal the sum of both triangles' normals. The encoder takes it, with the j and plane
//   choice, when it saves at least 3/4 bit a vertex (predictive_node.cpp: it costs the decoder about 110
//   instructions a vertex). Measured offline before building it (refined_elephant, residual symbols' order-0
//   entropy per vertex, the average of every parallelogram the whole mesh offers): level 0 14.02 -> 12.40
//   bits, levels >= 1 21.65 -> 20.89; the traversal's second parallelogram alone takes refined_elephant to
//   259,949 B (all three further ones found: 258,969), with the threshold 261,306 (-3.6 %; positions at level
//   0 0.95 -> 0.86 B a stored triangle after zstd). `bench decode --runs 1` (callgrind):
//   refined_elephant 91.1 -> 96.3 M instructions, elephant_1m (no node takes it) 1,188.9 -> 1,185.7 M.
//   Vertices without a second parallelogram predicted as single ones (no average of a parallelogram with
//   itself, no copy of their predictors into the second's place): refined_elephant 93.7 -> 92.7 M.
// Normals: predicted from the decoded positions, plain or smoothed (predicted_normals.hpp).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "package/coarse_positions.hpp"
#include "package/node_header.hpp"
#include "package/traversal_connectivity.hpp"

namespace lodstream::package {

// Header flag (node_header.hpp) of a node whose positions use the plane prediction (above).
constexpr uint32_t kPlanePrediction = 16;
// Header flag of a node whose positions use the multi-parallelogram prediction (above; codec 3 only).
constexpr uint32_t kMultiParallelogram = 128;

struct PredictiveNode : NodeHeader {
  uint32_t position_bytes = 0, normal_bytes = 0;
  uint32_t damping = 4;  // j of the position prediction
  bool smooth_normals = false;
  size_t header_size = 0;
  std::span<const uint8_t> position_planes, normal_planes, attribute_stream, locked_stream, connectivity,
      tail;

  // Reads and validates the layout (NodeHeader::read's checks for `format` and `known_flags`, widths, sizes
  // that add up); throws lodstream::Error starting with `where`. Cost: O(1).
  static PredictiveNode parse(std::span<const uint8_t> bytes, uint8_t format, uint32_t known_flags,
                              const std::string& where);
  // The parts of a node of `node_size` bytes from its first bytes (NodeCodec::layout; the tail counts as
  // connectivity), checked as parse checks them; `tail` receives the tail's size. Cost: O(1).
  static NodeSizeBreakdown layout(std::span<const uint8_t> bytes, size_t node_size, uint8_t format,
                                  uint32_t known_flags, const std::string& where, uint64_t* tail = nullptr);
};

// The encoder's side. Residuals of the quantized node's coarse coordinates against `predictors` (3 per
// vertex, as above), and the normals' against the prediction from the decoded positions over `indices` (the
// triangles as the decoder will see them, numbered from first_vertex; `locked_stream` the node's,
// encode_locked_stream); then the node's bytes. Cost: O(T + V).
struct PredictiveResiduals {
  std::vector<uint64_t> positions, normals;
  uint32_t position_bytes = 0, normal_bytes = 0;
  uint32_t damping = 4;  // j
  bool plane = false;    // kPlanePrediction
  bool multi = false;    // kMultiParallelogram
  bool smooth_normals = false;
};
PredictiveResiduals predictive_residuals(const NodeGeometry& geometry, const QuantizedNode& node,
                                         std::span<const uint32_t> predictors,
                                         std::span<const uint32_t> multi_predictors,
                                         const Parallelograms* extra, std::span<const uint32_t> indices,
                                         std::span<const uint8_t> locked_stream, const PositionGrid& grid);
std::vector<uint8_t> write_predictive_node(const NodeHeader& header, const PredictiveResiduals& residuals,
                                           std::span<const uint8_t> attribute_stream,
                                           std::span<const uint8_t> locked_stream,
                                           std::span<const uint8_t> connectivity,
                                           std::span<const uint8_t> tail);

// The decoder's side: out.mesh.positions, and out.mesh.normals, UVs, colours and vertex_data (each cleared
// without) of a parsed node whose out.mesh.indices are decoded, from `predictors` (3V entries or more; any
// values: they index entries below V + 1 only; the builds give the same bits where each vertex's lie below
// it or are V, as decode_traversal's and the predictive codec's do). Throws lodstream::Error starting with
// `where` on positions off the grid's range. Cost: O(T + V); the positions' residual planes, predictions and
// range check on this project's EPYC 6.7 TSC ticks a vertex with AVX-512 (x86-64-v4), 11.6 with AVX2
// (elephant_1m; motorBike 12.3 with AVX-512, most of its nodes plane-predicted; their prediction alone 12.0
// with AVX-512, 19.2 with AVX2).
void decode_predicted_vertices(const PredictiveNode& node, std::span<const uint32_t> predictors,
                               const Parallelograms* extra, const PositionGrid& grid, DecodedNode& out,
                               const std::string& where);

// decode_predicted_vertices with the positions' residual planes, predictions and range check as the baseline
// x86-64 build (SSE2) computes them whatever the CPU: the reference that the AVX2 and AVX-512 builds equal to
// the bit (tests compare them). The functions it calls (decode_positions, the normals') pick their builds
// as for decode_predicted_vertices.
void decode_predicted_vertices_baseline(const PredictiveNode& node, std::span<const uint32_t> predictors,
                                        const Parallelograms* extra, const PositionGrid& grid,
                                        DecodedNode& out, const std::string& where);

// decode_predicted_vertices' AVX2 build whatever wider one the CPU has, for tests to compare with the
// baseline on CPUs that run the AVX-512 build; call it only where __builtin_cpu_supports("avx2").
void decode_predicted_vertices_avx2(const PredictiveNode& node, std::span<const uint32_t> predictors,
                                    const Parallelograms* extra, const PositionGrid& grid, DecodedNode& out,
                                    const std::string& where);

}  // namespace lodstream::package
