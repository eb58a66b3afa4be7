// The multi-parallelogram prediction of the predictive codecs (predictive_node.hpp, predictor code 3): a
// vertex v is predicted as the mean of the damped parallelograms across the edges of every triangle that v
// closes (Cohen-Or, Cohen & Irony 2002, "Multi-way Geometry Encoding"; Isenburg & Alliez 2002, "Compressing
// Polygon Mesh Geometry with Parallelogram Prediction", IEEE Visualization): a triangle (v, x, y) with x, y <
// v and, across its edge x-y, a triangle (y, x, z) with z < v give the parallelogram (x, y, z). Positions are
// decoded after the connectivity, so every such triangle is known when v is. On the simplified meshes of
// coarse levels a single parallelogram predicts poorly (their sampling is irregular); the mean of a vertex's
// 1-4 averages the error down. Chosen per node by the encoder: packages -0.4 % (motorBike) to -1.1 %
// (elephant_1m, refined_elephant); decoding a node that uses it costs ~125 more instructions per triangle
// (find_parallelograms) plus the means.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace lodstream::package {

// A vertex keeps at most kMaxParallelograms parallelograms (the first ones in triangle order; few vertices
// of a coarse level close more), and the search for the triangle across an edge looks at the first
// kMaxLeaving half-edges leaving a vertex (in triangle order): fixed slots instead of lists keep the
// decoder's search short.
constexpr uint32_t kMaxParallelograms = 4, kMaxLeaving = 8;

// Per vertex v of a node, its parallelograms: (x, y, z) = corners[3 (kMaxParallelograms v + i) ..] for i <
// count[v], every one below v, in the order of the triangles that v closes.
struct Parallelograms {
  std::vector<uint8_t> count;     // V entries
  std::vector<uint16_t> corners;  // 3 kMaxParallelograms V entries: x y z per parallelogram
};

// The parallelograms of the V <= 65536 vertices of a node whose triangles `indices` are numbered from
// first_vertex (triangles with a corner outside [first_vertex, first_vertex + V) or a repeated corner take no
// part). Triangle t contributes to its largest corner v, across its edge x -> y opposite v, when the first
// triangle before t among those of y's kept half-edges that ends at x has its third corner z below v. Cost:
// O(T + V), one pass: per triangle a scan of at most kMaxLeaving slots and three stores; thread-local
// scratch.
void find_parallelograms(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t V,
                         Parallelograms& out);

// The multi-parallelogram prediction P (x y z) of a vertex from its `count` parallelograms (1 <= count <=
// kMaxParallelograms; x y z each, vertices of c, which holds x y z per vertex), each damped with j = 3 as in
// predictive_node.hpp:
//   P = floor((sum over i of (7 (c[x_i] + c[y_i]) - 6 c[z_i]) + 4 count) / (8 count)),
// the mean of the damped parallelograms m + 3/4 (m - c[z]), m = (c[x] + c[y]) / 2, in exact integers
// (floor(s / 8n) = floor(floor(s / 8) / n): shifts, and a division by 3). Sums wrap (uint64), so hostile
// coordinates never overflow. Cost: O(count).
inline void multi_parallelogram(const uint64_t* c, const uint16_t* xyz, uint32_t count, uint64_t* P) {
  uint64_t sum[3] = {4 * uint64_t(count), 4 * uint64_t(count), 4 * uint64_t(count)};
  for (uint32_t i = 0; i < count; ++i, xyz += 3) {
    const uint64_t *x = c + 3 * size_t(xyz[0]), *y = c + 3 * size_t(xyz[1]), *z = c + 3 * size_t(xyz[2]);
    for (int a = 0; a < 3; ++a) sum[a] += 7 * (x[a] + y[a]) - 6 * z[a];
  }
  for (int a = 0; a < 3; ++a) {
    const int64_t eighth = int64_t(sum[a]) >> 3;  // |eighth| < 2^61
    P[a] = uint64_t(count == 3 ? (eighth - (eighth < 0 ? 2 : 0)) / 3 : eighth >> (count / 2));
  }
}

}  // namespace lodstream::package
