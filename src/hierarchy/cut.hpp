// The cut rule and the crack test (DESIGN.md, Data model):
//   screen-space error e_px = e_obj * H / (2 * d * tan(fov_y / 2)), d = distance from the eye to the bounding
//   sphere, clamped at a small positive value;
//   a node is in the cut when its own error projects to <= tau pixels and its parents' to > tau.
// Distances are computed in double precision: with parents' spheres containing their children's (radius
// raised by 1e-5, bounding_sphere.hpp) and parents' errors >= children's, the projected error is then
// monotonic along the DAG for every eye, which is what makes the cut a consistent surface.
// The crack test welds the cut's triangles by position and compares its boundary edges (edges of exactly one
// triangle) with the full-resolution surface's.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/mesh.hpp"
#include "hierarchy/position_index.hpp"

namespace lodstream::hierarchy {

struct CutView {
  glm::dvec3 eye{0.0};
  double viewport_height = 1080.0;    // H, pixels
  double fov_y = 1.0471975511965976;  // radians (60 degrees)
  double min_distance = 1e-6;         // the clamp of d
};

// e_px of an error `error` bounded by `sphere` (formula above); +inf for an infinite error.
double screen_error(float error, const Sphere& sphere, const CutView& view);

// The cut rule: own error projects to <= tau and the parents' to > tau.
bool in_cut(float error, const Sphere& sphere, float parent_error, const Sphere& parent_sphere,
            const CutView& view, double tau);

// Welds triangle soups by exact position, shared by every mesh given to it.
class SurfaceWelder {
 public:
  // `mesh`'s triangles as position ids, three per triangle; triangles with a repeated position are dropped.
  std::vector<uint32_t> weld(const Mesh& mesh);
  const glm::vec3& position(uint32_t id) const { return positions_[id]; }

 private:
  PositionIndex index_;
  std::vector<glm::vec3> positions_;
};

// Edges (pairs of position ids, min << 32 | max) used by exactly one triangle of the union of `parts`
// (each part: three position ids per triangle), sorted. Cost: O(T log T), parallel sort.
std::vector<uint64_t> boundary_edges(std::span<const std::vector<uint32_t>* const> parts);

// "" when `cut` and `reference` hold the same boundary edges, else a one-line description of the first edge
// that differs ("boundary edge (x,y,z)-(x,y,z) is in the cut but not in the full-resolution surface").
std::string compare_boundaries(const std::vector<uint64_t>& cut, const std::vector<uint64_t>& reference,
                               const SurfaceWelder& welder);

}  // namespace lodstream::hierarchy
