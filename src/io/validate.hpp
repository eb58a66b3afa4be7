// Checks a freshly read mesh before lodstream uses it: what is invalid becomes an Error, what is merely
// useless (degenerate triangles) is dropped and counted.
#pragma once

#include <string>

#include "core/mesh.hpp"

namespace lodstream {

struct ValidationCounts {
  size_t degenerate_triangles = 0;  // dropped: two corners at the same position, or zero area
  bool dropped_normals = false;     // some normal was not finite: normals are recomputed instead
};

// Throws lodstream::Error("<what>: ...") when an index is out of range, a position is NaN or infinite (naming
// the vertex), a UV or colour is not finite, or an attribute array's length differs from the position count.
// Drops triangles that repeat a position or have zero area (cross product exactly 0, computed in double) and
// unreferenced attribute arrays stay as they are. Cost: O(V + T).
ValidationCounts validate_mesh(Mesh& mesh, const std::string& what);

}  // namespace lodstream
