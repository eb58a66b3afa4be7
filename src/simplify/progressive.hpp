// Progressive ("totally ordered") meshes (Bouvier & Gobbetti's TOM, seed 002 digest §2): the half-edge
// collapse sequence of simplify_mesh recorded as vertex substitutions u_s -> v_s and stored as an ordering.
// Vertices: the never-removed base first, then the removed ones, the first removed last (u_s gets index
// V - 1 - s), so the mesh after k substitutions uses exactly the vertices [0, V - k). Triangles: sorted by
// the vertex whose removal degenerates them, survivors first, so the triangles alive with nv vertices are a
// prefix. Each triangle keeps its full-resolution corners; a corner x >= nv resolves through parent[x] < x.
// Overhead over the plain mesh: one 32-bit index per vertex (parent).
//
// A seam collapse is two substitutions (its two wedges): between them the two sides of the seam are apart
// for one vertex count; extraction at any vertex count still gives a valid mesh (indices in range, no
// triangle that repeats a vertex), and the error bound holds at the step's two ends.
#pragma once

#include <cstdint>
#include <vector>

#include "core/mesh.hpp"
#include "simplify/simplify.hpp"

namespace lodstream::simplify {

struct ProgressiveMesh {
  Mesh mesh;  // vertices and triangles in the total order, full-resolution indices
  std::vector<uint32_t>
      parent;                // per vertex: the vertex it is substituted by (< its index); UINT32_MAX: base
  size_t base_vertices = 0;  // vertices never removed
  // Build output, not part of the streamed form: per vertex i >= base_vertices, the mesh's two-sided error
  // bound (model units) once it has i vertices (non-decreasing as i falls); 0 for base vertices.
  std::vector<float> error;
  // Build output: per vertex i >= base_vertices, whether i vertices is a whole-collapse boundary (false where
  // vertices i - 1 and i are the two wedges of one seam collapse: the seam is apart there); true below.
  std::vector<uint8_t> boundary;
};

// Simplifies `mesh` by half-edge collapses as far as they go (Options::target_triangles and max_error
// still stop it early; record_collapses and half_edge are forced) and orders the result. Welded duplicates
// are merged and unreferenced vertices dropped. Cost: simplify_mesh plus O(T log T + chain hops).
ProgressiveMesh build_progressive(const Mesh& mesh, Options options);

// Vertex count of the finest prefix with at most `max_triangles` triangles; base_vertices when even the
// base mesh has more. Cost: one chain walk.
size_t vertex_count_for(const ProgressiveMesh& pm, size_t max_triangles);

// Triangles alive with `vertex_count` vertices (clamped to [base_vertices, V]): the length of the triangle
// prefix that extract() returns. Cost: O(log T) chain walks.
size_t triangle_count_for(const ProgressiveMesh& pm, size_t vertex_count);

// The mesh with `vertex_count` vertices (clamped to [base_vertices, V]): the vertex prefix and the triangle
// prefix with every corner resolved to a vertex below `vertex_count`. Cost: O(triangles + chain hops).
Mesh extract(const ProgressiveMesh& pm, size_t vertex_count);

}  // namespace lodstream::simplify
