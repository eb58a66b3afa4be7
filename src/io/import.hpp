// Import of model files into lodstream's Scene (DESIGN.md, module io).
#pragma once

#include <filesystem>

#include "core/scene.hpp"

namespace lodstream {

struct ImportOptions {
  // Normals sharper than this stay seams when welding flat-shaded or normal-less input (see weld.hpp).
  float crease_angle_degrees = 60.0f;
  // Program run as `WORKER import-worker FILE OUTFILE` for formats read by assimp. Empty: this program when
  // it is `lodstream` (it registers itself, see import_worker.hpp), else a `lodstream` next to this program's
  // file.
  std::filesystem::path worker;
  // The worker is killed and the import fails after this many seconds.
  double worker_timeout_s = 300.0;
};

// Reads a model file into a Scene: objects with names and transforms, meshes (positions, normals, UVs,
// colours), materials (base colour, absolute base-colour texture path). PLY, OFF and OBJ (by extension, any
// case) are read in process by fast readers; every other format (STL, glTF 2.0 / GLB, 3DS, DAE, FBX, ...) by
// assimp in a child process, so that a crashing importer cannot take lodstream down. glTF node hierarchies
// become object transforms; a mesh referenced by several nodes is stored once (instances).
//
// Every mesh is then validated and welded (validate.hpp, weld.hpp): vertices equal in position and all
// attributes are merged (seams stay seams); flat-shaded or normal-less meshes are welded by position and get
// normals that keep creases sharper than `crease_angle_degrees`. Degenerate triangles (repeated position,
// zero area) are dropped with one warning line on standard error giving the count; objects left without
// triangles are dropped. UVs follow the OBJ / OpenGL convention: (0,0) is the bottom-left corner of the
// image.
//
// Throws lodstream::Error("<file>: <reason>") on any failure (missing file, bad header, truncated data, huge
// declared counts, NaN or infinite coordinates, out-of-range indices, no triangles at all; for assimp formats
// "<file>: import failed: <reason>" when the worker crashes, times out, exits non-zero or returns garbage).
// Never crashes on bad input. Cost: O(file size); about 1 s per 5M triangles of binary PLY on one core; OBJ
// is parsed, and the meshes of a scene validated and welded, on all cores.
Scene import_model(const std::filesystem::path& file, const ImportOptions& options = {});

}  // namespace lodstream
