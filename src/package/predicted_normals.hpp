// Normals predicted from the decoded geometry, as the predictive codecs store them: the prediction of vertex
// v is the area-weighted sum of the normals of the node's own triangles around v over the DECODED positions,
// sum of cross(p1 - p0, p2 - p0) (Gouraud's smooth normal). A node stores the normal as the octahedral code
// (octahedral.hpp) of its coordinates in an orthonormal frame (t, b, p) around the unit prediction p: the
// code of p itself is (0, 0), so a well predicted normal stores small values, and the same angular error
// costs the same codes wherever the prediction points (the global octahedral code is about pi times denser in
// area around its poles than on average). The codes are zigzag-mapped, as byte planes (byte_planes.hpp;
// byte b of component a at plane 2b + a). Interior vertices of a smooth mesh mostly store 0; seams and
// creases store what they differ by. The frame is discontinuous where p.z changes sign, so the decoder must
// build it from the same bits as the encoder: both use the same lane-wise functions on the same sums.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "package/octahedral.hpp"

namespace lodstream::package {

// A predicted normal (x, y, z, unused) as one SIMD register (GCC / Clang vector extension): the sum of
// cross products is 3 vector operations and a 4-lane cross product per triangle instead of 27 scalar ones,
// bit-identical to the scalar formula (the same products and differences, in the same order, no
// contraction).
using NormalSum = Float4;

// sum[v] for v < V (and zeros up to a multiple of 4 entries): the unnormalized prediction over `positions`
// from the triangles whose corners are all in the node (indices minus first_vertex below V). `index_end`
// bounds the indices (checked by the caller); when it is first_vertex + V (every node but a progressive step)
// no corner lies outside and the loop tests none. With `smooth`, the sums are then smoothed over the
// one-ring: s'[v] = 2 s[v] + sum over v's triangles (v, a, b) of s[a] + s[b], which averages out the tilt
// that quantized positions give the faces of a finely tessellated smooth surface (elephant_1m's level 0
// stores 25 % fewer normal bytes) and blurs creases (motorBike would store 80 % more: the encoder chooses per
// node). Cost: O(T + V), one cross product per triangle, with `smooth` a second pass over the triangles.
void predicted_normals(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t index_end,
                       const glm::vec3* positions, uint32_t V, bool smooth, std::vector<NormalSum>& sum);

// The encoder's choice: the codes (normal_residuals) of normals[order[v]] against the prediction plain and
// smoothed (predicted_normals), whichever takes fewer bits; `smooth` says which. Cost: twice
// predicted_normals and normal_residuals.
struct NormalCodes {
  std::vector<uint64_t> codes;
  uint32_t width = 0;
  bool smooth = false;
};
NormalCodes code_normals(std::span<const glm::vec3> normals, std::span<const uint32_t> order,
                         std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t index_end,
                         const glm::vec3* positions, uint32_t bits);

// The zigzagged codes (2 per vertex v < order.size()) of normals[order[v]] in the frame of sum[v], rounded
// toward the prediction with a dead zone at 9 bits and fewer (predicted_normals.cpp's rounding_offset: the
// error stays below 0.8 code steps at 9 bits, 0.6 below; more bits round to the nearest code), and in `width`
// the bytes per code (1..3) the planes need. Cost: O(V), a frame and an octahedral encode per vertex.
std::vector<uint64_t> normal_residuals(std::span<const glm::vec3> normals, std::span<const uint32_t> order,
                                       std::span<const NormalSum> sum, uint32_t bits, uint32_t& width);

// normals = V entries decoded from the code planes (2 * width * V bytes; hostile codes are clamped, never
// overflow) in the frames of sum[v], with octahedral.hpp's 16-, 8- and 4-lane decodes. Cost: O(V), one pass
// of 16-lane frames and decodes on a CPU with AVX-512 (x86-64-v4), of 8 lanes with AVX2, of 4 on others
// (narrower steps for the last vertices); on this project's EPYC 3.3, 4.2 and 10.5 TSC ticks a vertex, where
// the 8-lane AVX2 build alone took 5.3 (rdtsc over the nodes of refined_elephant and elephant_1m).
void decode_predicted_normals(std::span<const NormalSum> sum, uint32_t V, const uint8_t* planes,
                              uint32_t width, uint32_t bits, std::vector<glm::vec3>& normals);

// decode_predicted_normals as the baseline x86-64 build (SSE2, 4 lanes) computes it whatever the CPU: the
// reference that the AVX2 and AVX-512 builds equal to the bit (tests compare them).
void decode_predicted_normals_baseline(std::span<const NormalSum> sum, uint32_t V, const uint8_t* planes,
                                       uint32_t width, uint32_t bits, std::vector<glm::vec3>& normals);

}  // namespace lodstream::package
