// The world-space bounds of a package's scene (what generated camera paths and the viewer's start pose fit).
#pragma once

#include "core/bounds.hpp"
#include "package/index.hpp"

namespace lodstream::cli {

// The union of every object's representation bounds under the object's transform. O(objects).
Bounds world_bounds(const package::PackageScene& scene);

}  // namespace lodstream::cli
