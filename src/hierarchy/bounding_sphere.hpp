// Bounding spheres of node geometry and of groups of nodes (DESIGN.md, Data model: a parent's sphere contains
// its children's).
#pragma once

#include <glm/glm.hpp>
#include <span>

#include "core/bounds.hpp"

namespace lodstream::hierarchy {

// A sphere containing every point: Ritter's two-pass approximation (at most about 5 % larger than the
// minimal one), grown so that float rounding never leaves a point outside. Cost: O(n).
Sphere sphere_of_points(std::span<const glm::vec3> points);

// A sphere containing every sphere of `spheres` (Ritter-style growth from the largest one), then every point
// of `points`, with its radius raised by a relative 1e-5 so that containment survives float rounding of
// later distance computations. Cost: O(n + m).
Sphere sphere_of_spheres(std::span<const Sphere> spheres, std::span<const glm::vec3> points = {});

}  // namespace lodstream::hierarchy
