// Small meshes built in code for unit tests.
#pragma once

#include "core/mesh.hpp"

namespace lodstream::test {

// Unit sphere (radius r, centre 0) from `rings` x `segments` quads; closed and manifold, one position per
// vertex (no seams), smooth normals. Triangles: 2 * segments * (rings - 1).
Mesh sphere(float r = 1.0f, int rings = 32, int segments = 64);

// The same sphere with UVs: a UV seam along one meridian (duplicated positions with different UVs).
Mesh uv_sphere(float r = 1.0f, int rings = 32, int segments = 64);

// Flat n x n grid of quads in the z = z0 plane covering [0,1]^2; it has a boundary. Triangles: 2 n^2.
Mesh grid(int n = 16, float z0 = 0.0f);

// Unit cube [-1,1]^3 with one vertex per face corner (24 vertices, flat per-face normals, normal seams along
// every edge) and `subdivisions` x `subdivisions` quads per face.
Mesh cube_with_seams(int subdivisions = 1);

// Non-manifold cases: three triangles sharing one edge, plus two triangles touching at one vertex only.
Mesh non_manifold();

}  // namespace lodstream::test
