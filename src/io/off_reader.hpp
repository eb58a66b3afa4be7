// Fast OFF reader (Geomview Object File Format, ascii). Hand-written: a few dozen lines, read in place.
#pragma once

#include <filesystem>

#include "core/scene.hpp"

namespace lodstream {

// Reads `[ST][C][N]OFF` files: '#' comments, counts on the keyword's line or the next, vertices
// `x y z [nx ny nz] [r g b [a]] [s t]` (colours as 0..255 integers or 0..1 floats), polygons `n i1 .. in
// [colour]` triangulated as fans. 4OFF, nOFF and binary OFF are rejected. Returns a one-object scene whose
// mesh is NOT yet validated or welded; indices are checked. Throws lodstream::Error("<file>:<line>:
// <reason>") on malformed, truncated or oversized input (declared counts are checked against the file size
// before allocating). Cost: O(file size).
Scene read_off(const std::filesystem::path& file);

}  // namespace lodstream
