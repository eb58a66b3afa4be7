// The private binary form in which the import worker hands a Scene to its parent process. Same machine, same
// build: native little-endian layout, no versioning beyond a magic string.
#pragma once

#include <string>

#include "core/scene.hpp"

namespace lodstream {

// Layout: "LODSCN01", then u32 counts and, per material, name / base colour / texture; per mesh, the vertex
// count, attribute flags, material and arrays; per object, name, 16 floats of transform and a mesh index.
std::string encode_scene(const Scene& scene);

// Decodes what encode_scene wrote. Never trusts the bytes: every count is checked against the bytes left and
// every cross-reference (object → mesh, mesh → material) against its range. Index ranges are checked later by
// validate_mesh. Throws lodstream::Error("<what>: <reason>"). Cost: O(size).
Scene decode_scene(const char* data, size_t size, const std::string& what);

}  // namespace lodstream
