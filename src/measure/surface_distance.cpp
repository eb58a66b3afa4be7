#include "measure/surface_distance.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "measure/world_surface.hpp"

namespace lodstream {

namespace {
SurfaceDistance measure_world_surfaces(const Mesh& a, const Mesh& b, const DistanceOptions& options) {
  if (a.triangle_count() == 0) throw Error("surface A has no triangles");
  if (b.triangle_count() == 0) throw Error("surface B has no triangles");
  SurfaceDistance result;
  result.a_to_b = ReferenceSurface(b).distance_from(a, options);
  result.b_to_a = ReferenceSurface(a).distance_from(b, options);
  const OneSidedDistance& ab = result.a_to_b;
  const OneSidedDistance& ba = result.b_to_a;
  result.hausdorff = std::max(ab.max, ba.max);
  const double area = ab.area + ba.area;
  if (area > 0) {
    result.mean = (ab.area * ab.mean + ba.area * ba.mean) / area;
    result.rms = std::sqrt((ab.area * ab.rms * ab.rms + ba.area * ba.rms * ba.rms) / area);
  }
  result.samples = ab.samples + ba.samples;
  return result;
}
}  // namespace

SurfaceDistance measure_surface_distance(const Scene& a, const Scene& b, const DistanceOptions& options) {
  return measure_world_surfaces(world_surface(a), world_surface(b), options);
}

SurfaceDistance measure_surface_distance(const Mesh& a, const Mesh& b, const DistanceOptions& options) {
  return measure_world_surfaces(a, b, options);
}

}  // namespace lodstream
