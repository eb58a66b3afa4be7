// Fast PLY reader (ascii, binary little endian, binary big endian). Hand-written because no Debian library
// reads PLY at the speed lodstream needs (assimp takes about 6 s for 5.7M triangles; this reads the file
// memory-mapped, in place, with one switch per property and no per-element virtual calls).
#pragma once

#include <filesystem>

#include "core/scene.hpp"

namespace lodstream {

// Reads the `vertex` element (x,y,z; nx,ny,nz; u,v or s,t or texture_u,texture_v or texture_s,texture_t;
// red,green,blue[,alpha] as integers scaled to [0,1] or floats) and the `face` element's
// vertex_indices / vertex_index list (polygons triangulated as fans; faces of fewer than 3 corners skipped).
// Other elements and properties are skipped. Returns a one-object scene whose mesh is NOT yet validated or
// welded (import_model does that); indices are checked against the vertex count.
// Throws lodstream::Error("<file>: <reason>") naming the byte offset (binary) or line (ascii) of a bad
// header, truncated data, out-of-range index or a declared count larger than the file can hold. Cost: O(file
// size).
Scene read_ply(const std::filesystem::path& file);

}  // namespace lodstream
