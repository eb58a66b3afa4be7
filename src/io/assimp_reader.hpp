// assimp, for every format without a fast reader. Runs only inside the import worker process (assimp crashes
// on some files); lodstream code calls import_model instead.
#pragma once

#include <filesystem>

#include "core/scene.hpp"

namespace lodstream {

// Reads `file` with assimp (triangulated; points and lines dropped). The node hierarchy becomes object
// transforms (parent * local); a node with several meshes becomes several objects "node#k"; an assimp mesh
// referenced by several nodes is stored once. Materials: base colour (glTF) or diffuse colour, with opacity
// as alpha; base-colour or diffuse texture as an absolute path (embedded textures are not extracted: warned
// and left out). Meshes are NOT welded or validated. glTF files using KHR_mesh_quantization are rejected
// because assimp 5.2 misreads their positions. Throws lodstream::Error("<file>: <assimp's reason>").
Scene read_with_assimp(const std::filesystem::path& file);

}  // namespace lodstream
