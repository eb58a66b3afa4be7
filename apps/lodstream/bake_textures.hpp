// Textures of a bake: each material's base-colour image file is stored in the package as a blob (the file's
// bytes as they are: PNG or JPEG), so a package is complete wherever it is served or copied — a client far
// from the model's folder still draws the textures (issue 4: "nothing is lost"). Texture streaming by mip
// level can replace this later; today a client reads a material's whole image when it first draws it.
#pragma once

#include <vector>

#include "core/scene.hpp"
#include "package/writer.hpp"

namespace lodstream::cli {

// The package materials of `materials`: each readable texture file becomes a blob of `writer` (one per file,
// however many materials use it) and the material keeps only the file's name; a file that cannot be read is
// a warning on standard error and stays a path. Cost: reads each texture file once.
struct EmbeddedTextures {
  std::vector<package::PackageMaterial> materials;
  uint64_t bytes = 0;  // of the blobs written
};
EmbeddedTextures embed_textures(const std::vector<Material>& materials, package::PackageWriter& writer);

}  // namespace lodstream::cli
