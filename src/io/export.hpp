// Export of a scene to a model file, for debugging and for handing results to other tools.
#pragma once

#include <filesystem>

#include "core/scene.hpp"

namespace lodstream {

// Writes all objects (transforms applied, instances expanded) as one file, chosen by extension:
//  - .ply: binary little endian; vertex x,y,z float, then nx,ny,nz float, s,t float and red,green,blue,alpha
//    uchar when any mesh has them (a mesh without gets smooth normals, UV 0, or its material's base colour);
//    face `list uchar int vertex_indices`.
//  - .obj: `o` per object, `usemtl` per material, v / vt / vn / f with shortest round-trip number text; the
//    materials (Kd, d, map_Kd) go to FILE.mtl next to it.
// Written through a temporary file and a rename. Throws lodstream::Error("<file>: <reason>") for an unknown
// extension or a write failure. Cost: O(triangles as drawn).
void export_scene(const Scene& scene, const std::filesystem::path& file);

}  // namespace lodstream
