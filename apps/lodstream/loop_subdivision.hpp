// Loop subdivision of a triangle mesh, used to make the large test inputs (1.4M / 5.7M triangles) from a real
// scan. Wraps OpenMesh's LoopT (Debian's libopenmesh-dev) rather than writing it again.
#pragma once

#include "core/mesh.hpp"

namespace lodstream::cli {

// Applies `levels` rounds of Loop subdivision (each multiplies the triangle count by 4) to the positions and
// connectivity of `mesh`; other attributes are dropped (normals are recomputed by whoever loads the result).
// Deterministic. Cost: O(4^levels · T) time and memory.
Mesh loop_subdivide(const Mesh& mesh, int levels);

}  // namespace lodstream::cli
