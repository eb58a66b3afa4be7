// Screen-space error and frustum culling of bounding spheres (DESIGN.md, Data model):
//   e_px = e_obj * H / (2 * d * tan(fov_y / 2)),
// d = distance from the eye to the bounding sphere (|eye - center| - radius), clamped at a small positive
// value, H = viewport height in pixels, fov_y vertical. Node errors and spheres are in object units; an
// object's transform moves the sphere and scales sphere and error by the transform's largest axis scale
// (an upper bound for a non-uniform scale). Everything is in double precision so that, with parents'
// spheres containing their children's and parents' errors at least their children's, e_px is monotonic
// along a DAG for every eye (the property the cut relies on). Pure computation.
// (hierarchy/cut.hpp computes the same e_px in object space for the baker; runtime may not depend on
// hierarchy in DESIGN.md's module table, so the client's world-space version lives here.)
#pragma once

#include <glm/glm.hpp>

#include "core/bounds.hpp"
#include "core/camera.hpp"

namespace lodstream::schedule {

struct WorldSphere {
  glm::dvec3 center{0.0};
  double radius = 0.0;
};

// What e_px and culling need of a camera: eye, orthonormal basis and the pinhole's scale.
struct View {
  glm::dvec3 eye{0.0};
  glm::dvec3 forward{0.0, 0.0, -1.0}, right{1.0, 0.0, 0.0}, up{0.0, 1.0, 0.0};
  double width = 1280.0, height = 720.0;  // viewport, pixels
  double tan_half_x = 0.0, tan_half_y = 0.0;
  double min_distance = 1e-6;  // the clamp of d (world units)

  // The view of a valid camera (validate_camera's conditions).
  static View of(const Camera& camera);
  // H / (2 tan(fov_y / 2)): pixels per unit of error at distance 1 (the focal length in pixels).
  double focal_pixels() const { return height / (2.0 * tan_half_y); }
};

// Largest axis scale of an affine transform's linear part (the longest transformed unit axis).
double max_scale(const glm::mat4& transform);
// `sphere` (object space) under `transform`, its radius multiplied by `scale` (= max_scale(transform)).
WorldSphere to_world(const Sphere& sphere, const glm::mat4& transform, double scale);

// d of the formula: |eye - center| - radius, at least view.min_distance.
double sphere_distance(const WorldSphere& sphere, const View& view);
// e_px of a world-space error bounded by `sphere`; +inf for an infinite error (a root's parent).
double screen_error(double world_error, const WorldSphere& sphere, const View& view);

// Whether any part of `sphere` may be inside the view frustum (the four side planes and the plane through
// the eye; no far plane). Conservative: a sphere near a frustum corner may be kept though outside.
bool in_frustum(const WorldSphere& sphere, const View& view);

}  // namespace lodstream::schedule
