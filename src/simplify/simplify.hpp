// Quadric edge-collapse simplification (Garland & Heckbert 97, attributes after Hoppe 99) with a tracked,
// conservative two-sided error bound: a radius r_v per vertex such that every point p of the simplified
// surface is within the barycentric interpolation r(p) of its triangle's radii of the input, and every input
// point within r(p) of some p (the LOD book digest, §7.5). A collapse gives x the smaller of two radii, each
// of which keeps that invariant through a mapping of the changed faces onto the new ones:
// - natural mapping (vertex merge, linear per face): r_x = max(r_a + |a - x|, r_b + |b - x|);
// - vertical mapping, on a fold-free closed star (projection onto the plane of its mean normal): points over
//   the same place correspond, so r_x is the least value with r_new(p') >= height gap + r_old(p), checked at
//   the vertices of the common refinement of both fans (0 growth on planar regions, about curvature x
//   length^2 on smooth ones instead of about length/2).
//
// Operator: edge collapse a -> b with optimal placement x (full edge) or x = b (half edge). Framework: passes
// of independent collapses in quadric-cost order (a lazy queue: each pass re-evaluates, in parallel, the
// edges with an end touched by the previous one and sorts the candidates), each pass limited to 1.5x
// the cost of the collapse that would reach the target, which keeps the order close to greedy. A collapse
// that fails the validity checks is not tried again until an end is touched (or a pass finds nothing). The
// collapse loop of a large pass runs on many small regions (runs of about 16384 alive vertices in Morton
// order, at least 2 runs, shifted each pass) on both cores, the collapses that cross a region's border after
// them, serially; the result does not depend on thread timing.
//
// Vertices are classified once (meshoptimizer's vertex kinds, extended): Manifold (interior), Border (one
// open edge in and out), Seam (two vertices share the position and their open edges pair up: a UV, normal
// or colour seam), Locked (user lock, non-manifold edge or fan, seam junctions, more than two wedges).
// Border and seam vertices only collapse along their border / seam (a seam collapse moves both sides
// together); locked vertices never move or disappear; anything may collapse into a locked vertex.
// Validity of every collapse: link condition (no non-manifold edge or vertex, no boundary pinch, no lost
// surface), no triangle normal turning by more than `max_normal_change_deg`, no new degenerate triangle.
// Input with exact duplicate vertices is welded first; triangles that repeat a vertex are dropped.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/mesh.hpp"

namespace lodstream::simplify {

struct Options {
  // Stop conditions: the first one met ends simplification. A triangle target is met within 1 % when the
  // mesh can be reduced that far; `max_error` (model units) is never exceeded by the returned error bound.
  size_t target_triangles = 0;
  double max_error = std::numeric_limits<double>::infinity();

  // Attribute weights in the collapse cost (attribute units per unit of the bounding-box extent): 0 drops the
  // attribute from the cost (it is still interpolated). All 0 gives the positions-only metric.
  float normal_weight = 0.01f;
  float uv_weight = 0.05f;
  float color_weight = 0.05f;
  // Weight of the boundary / seam penalty planes (Garland & Heckbert's perpendicular planes), times |e|^2.
  float boundary_weight = 20.0f;
  // A collapse is rejected when any remaining triangle's normal turns by more than this (degrees).
  float max_normal_change_deg = 80.0f;
  // Half-edge collapses only: the kept vertex keeps its position and attributes (progressive meshes).
  bool half_edge = false;
  // Per input vertex, non-zero = locked (never moves, never removed). Empty = none locked.
  std::vector<uint8_t> locked;
  // Per input vertex (model units): the radius r_v it already carries against a finer surface this mesh was
  // simplified from (a previous Result::vertex_error). Empty = 0, the input itself. The invariant above
  // holds through every mapping whatever the starting radii, so the result's vertex_error and error_bound
  // then bound the distance to that finer surface directly, not to this input (no sum of bounds).
  std::vector<float> vertex_error;
  // Record the collapse sequence in Result::collapses (used by progressive meshes).
  bool record_collapses = false;
  // When edge collapse stops short of target_triangles, continue with vertex clustering (cluster.hpp), which
  // may change topology; Result::error_bound then covers both steps and vertex_error holds in the
  // face-maximum form of cluster.hpp.
  bool allow_topology_change = false;
  // Called now and then with the fraction of the requested reduction done (0..1).
  std::function<void(float)> progress;
};

// One half-edge collapse (record_collapses): vertex `removed` merged into vertex `kept` (input numbering,
// after welding). A seam collapse is two records with the same `step`; `error_bound` is the mesh's two-sided
// bound after it (model units, non-decreasing).
struct Collapse {
  uint32_t removed;
  uint32_t kept;
  uint32_t step;
  float error_bound;
};

struct Result {
  Mesh mesh;                 // the simplified mesh; unused vertices are removed
  double error_bound = 0.0;  // >= symmetric Hausdorff distance(result, input), model units
  // Per output vertex (model units): r_v; every point of an output face is within the barycentric
  // interpolation of its corners' vertex_error of the input, and every input point within that of some point.
  std::vector<float> vertex_error;
  size_t input_triangles = 0;
  bool target_reached = true;        // false when no valid collapse was left before the triangle target
  std::vector<Collapse> collapses;   // with Options::record_collapses
  std::vector<uint32_t> weld_remap;  // input vertex -> welded vertex (Collapse numbering)
};

// Simplifies `mesh`. Cost: O(T log T) time over a few passes, using every core for the set-up (weld,
// quadrics, classification, sorts), cost evaluation and the collapse loop; memory about 130 bytes per input
// triangle (elephant_1m: 169 B/tri peak for the whole `lodstream simplify`, import and export included).
// Never throws on odd input (non-manifold, degenerate, empty).
Result simplify_mesh(const Mesh& mesh, const Options& options);

}  // namespace lodstream::simplify
