// OBJ reader: parses the file on every core (obj_chunk.hpp; Debian's tinyobjloader reads the MTL files) into
// lodstream's scene.
#pragma once

#include <filesystem>

#include "core/scene.hpp"

namespace lodstream {

// Reads an OBJ file (and the MTL libraries it names, searched next to it). One object per `o`/`g` group and
// material (a group using two materials becomes two objects, "group/material"), each with its own mesh in
// world coordinates (identity transform). Materials: Kd is the base colour, d its alpha, map_Kd the
// base-colour texture as an absolute path. Per-vertex colours (the `v x y z r g b` extension) are kept when
// present. Each mesh has one vertex per distinct corner (position, UV and normal index) in order of first
// use, and is NOT yet welded or validated (import_model does that); indices are checked. Throws
// lodstream::Error("<file>: <reason>"), "<file>:<line>: <reason>" for a bad number or index. Faces of four
// corners are split along the shorter diagonal, larger ones by tinyobjloader's ear clipping. The file is
// mapped and cut into chunks of about `chunk_bytes` at line breaks, parsed in parallel (tests make them tiny
// so that chunk borders fall everywhere). Cost: O(file size) over the cores; memory: the corners (12 bytes
// each) and vertices of the file besides the meshes.
Scene read_obj(const std::filesystem::path& file, size_t chunk_bytes = size_t(4) << 20);

}  // namespace lodstream
