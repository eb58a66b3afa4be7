// OBJ reader: Debian's tinyobjloader parses the file and its MTL; this turns the result into lodstream's
// scene.
#pragma once

#include <filesystem>

#include "core/scene.hpp"

namespace lodstream {

// Reads an OBJ file (and the MTL libraries it names, searched next to it). One object per `o`/`g` group and
// material (a group using two materials becomes two objects, "group/material"), each with its own mesh in
// world coordinates (identity transform). Materials: Kd is the base colour, d its alpha, map_Kd the
// base-colour texture as an absolute path. Per-vertex colours (the `v x y z r g b` extension) are kept when
// present. Meshes are per corner and NOT yet welded or validated (import_model does that); indices are
// checked. Throws lodstream::Error("<file>: <reason>"). Cost: O(file size); tinyobjloader holds the parsed
// file in memory.
Scene read_obj(const std::filesystem::path& file);

}  // namespace lodstream
