// Floating-cell vertex clustering (Low & Tan 97, LOD book digest §7.6.1) with quadric placement: vertices
// in grade order (locked first, then by how far their faces' normals spread) each take every unassigned
// vertex within the cell radius rho as a cluster; the cluster's representative minimises the sum of its
// members' face-plane quadrics (within rho of the leader, else the leader's position; a locked leader keeps
// its own), and triangles are mapped to clusters, dropping those that repeat a cluster and duplicates.
// Topology may change (holes close, components vanish); locked vertices never move or disappear, and no
// two locked vertices merge (a cell radius at which a locked vertex would lose all its triangles is too
// coarse). rho is found by bisection for the triangle target.
//
// Two-sided bound, in face-maximum form (weaker than simplify.hpp's interpolation: every point of an output
// face is within the largest vertex_error of its corners of the input, and every input point within that of
// some output face): the natural mapping moves each vertex to its cluster's
// representative, so points move at most the largest displacement of their triangle's corners; a dropped
// triangle's image (a segment or a point) lies within the distance of its corners' images to a used
// representative (the nearest one when none of them is used). A cluster's error is the largest, over the
// input triangles charged to it, of that distance plus the prior error of the triangle's corners.
#pragma once

#include <vector>

#include "core/mesh.hpp"
#include "simplify/simplify.hpp"

namespace lodstream::simplify {

// Clusters `mesh` to at most options.target_triangles (the closest count found below it; 0 = as few as the
// bisection reaches) without a bound above options.max_error; uses options.locked and no other field.
// `prior_error` (per vertex, model units, or empty) is the error the mesh already carries (its vertex_error
// from simplify_mesh; read in face-maximum form), added to the new bound. Result::target_reached is false
// when the count stays above the target. Cost: O((V + T) log) per bisection step, about 20 steps.
Result cluster_mesh(const Mesh& mesh, const Options& options, const std::vector<float>& prior_error = {});

}  // namespace lodstream::simplify
