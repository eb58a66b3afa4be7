// The world-space surface of a scene: every object's triangles with its transform applied, as one indexed
// triangle list (positions and indices only). Distances in src/measure are measured between such surfaces.
// This may belong in core (other modules flatten scenes too); it lives here until one of them needs it.
#pragma once

#include <glm/glm.hpp>

#include "core/mesh.hpp"
#include "core/scene.hpp"

namespace lodstream {

// Appends `mesh`'s triangles, transformed by `transform` (object to world), to `surface`. Only vertices that
// a triangle references are copied (unreferenced vertices are not part of the surface). `what` names the mesh
// in errors. Throws lodstream::Error on an index out of range or a non-finite (NaN, infinite) transformed
// position. Cost: O(V + T) time, one temporary array of V indices.
void append_world_surface(const Mesh& mesh, const glm::mat4& transform, Mesh& surface,
                          const std::string& what);

// The world-space surface of all of `scene`'s objects (an instanced mesh appears once per object).
// Throws as append_world_surface does. Cost: O(triangles as drawn).
Mesh world_surface(const Scene& scene);

}  // namespace lodstream
