// Vertex welding: turns per-corner or duplicated vertices into a shared-vertex mesh without erasing seams.
#pragma once

#include "core/mesh.hpp"

namespace lodstream {

struct WeldResult {
  size_t vertices_before = 0;
  size_t vertices_after = 0;
  bool normals_recomputed = false;  // the input had no normals, or flat-shaded ones
};

// Merges vertices that are equal in position AND every attribute (bitwise, -0 == +0), so UV, colour and
// normal seams stay seams; drops vertices no triangle references. Cost: O(V + T) with a hash table.
void weld_identical(Mesh& mesh);

// Welds by position (and UV and colour) ignoring the current normals, then computes normals with creases:
// at each position, the incident triangles are grouped so that a triangle joins the first group whose seed
// triangle's normal is within `crease_angle_degrees` of its own; each group gets the area-weighted mean of
// its triangles' normals (n = normalize(sum over faces of (p1 - p0) x (p2 - p0))) and its own vertex. Edges
// sharper than the crease angle stay seams; everything else is smooth. Cost: O(V + T) expected.
void weld_with_crease_normals(Mesh& mesh, float crease_angle_degrees);

// What import does with every mesh: weld_with_crease_normals when it has no normals; otherwise
// weld_identical, then weld_with_crease_normals when it looks flat-shaded (in at least 90% of the triangles
// the three corners carry one and the same normal, the triangle's own within 1 degree). Authored smooth
// normals are kept as they are.
WeldResult weld(Mesh& mesh, float crease_angle_degrees);

}  // namespace lodstream
