// A small object's multiresolution representation: its progressive (totally ordered) mesh
// (simplify/progressive.hpp, seed 002) cut into prefix steps, each one node of the package (DESIGN.md, Data
// model: "a progressive-mesh prefix step"). Step k holds vertices [v_k, v_k+1) of the order and triangles
// [t_k, t_k+1), the triangles alive with v_k+1 vertices but not with v_k; steps 0..j together are the mesh
// with v_j+1 vertices. Step 0 is the base mesh (v_1 = base vertices); step k > 0 adds about clamp(t_k,
// min_step, max_step) triangles: doubling near the base (a few coarse steps, each halving the error like a
// DAG level) and page-sized further up (max_step triangles, ~8-16 KB encoded).
//
// Triangles keep their full-resolution corners (what makes every later prefix right: a corner c drawn with nv
// vertices is c resolved through `parent` until it is below nv). A client holding steps 0..j knows the
// parents of its own vertices only, so each step also carries `chains`: (vertex, parent) for every vertex at
// or above its end on the substitution chain of one of its corners, those no earlier step carried. Then
// steps 0..j resolve every corner they hold: each chain vertex >= v_j+1 was carried by the step of the corner
// it came from. Every parent is carried once: the streamed form costs one index per vertex, as a TOM does.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/bounds.hpp"
#include "core/mesh.hpp"
#include "simplify/simplify.hpp"

namespace lodstream::hierarchy {

struct ProgressiveStep {
  // Vertices [first_vertex, first_vertex + vertex_count) of the order (indices count from 0 of the whole
  // mesh); triangles [first_triangle, first_triangle + triangle_count) of the order with full-resolution
  // corners, in vertex-cache order inside the step.
  Mesh mesh;
  uint32_t first_vertex = 0, first_triangle = 0;
  // The two-sided error bound (model units) of the prefix that ends with this step; 0 for the last one.
  float error = 0.0f;
  // (vertex, parent) pairs sorted by vertex (header): parent < vertex, vertex >= the step's end.
  std::vector<std::pair<uint32_t, uint32_t>> chains;
};

struct ProgressiveSteps {
  std::vector<ProgressiveStep> steps;  // errors non-increasing
  uint32_t vertices = 0;               // of the whole ordered mesh (every corner is below it)
  Sphere sphere;                       // contains every vertex: every prefix's surface (half-edge collapses)
  Mesh base;                           // step 0 as a plain mesh (corners resolved): what an HLOD merges
};

struct StepOptions {
  size_t min_step_triangles = 256;
  size_t max_step_triangles = 2048;
  simplify::Options simplify;  // for build_progressive
};

// Builds the progressive mesh of `mesh` and cuts it into steps (header). Step boundaries never split the
// two wedge substitutions of one seam collapse. An empty mesh gives no steps. Cost: build_progressive plus
// O(T log T + chain hops).
ProgressiveSteps build_progressive_steps(const Mesh& mesh, const StepOptions& options = {});

}  // namespace lodstream::hierarchy
