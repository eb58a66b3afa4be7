#include "schedule/screen_area.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lodstream::schedule {

double projected_area(const WorldSphere& sphere, const View& view) {
  const glm::dvec3 d = sphere.center - view.eye;
  const double x = glm::dot(d, view.right), y = glm::dot(d, view.up), z = glm::dot(d, view.forward);
  const double r = sphere.radius;
  if (z <= -r) return 0.0;
  if (z <= r) return view.width * view.height;
  const double f = view.focal_pixels();
  const double rho = f * r / std::sqrt(glm::dot(d, d) - r * r);
  const double cx = 0.5 * view.width + f * x / z, cy = 0.5 * view.height + f * y / z;
  // A disc inside the viewport (most nodes of a view) needs no clipping: pi rho^2.
  if (cx - rho >= 0.0 && cx + rho <= view.width && cy - rho >= 0.0 && cy + rho <= view.height)
    return std::numbers::pi * rho * rho;
  // Chords of the disc over the strips of y inside the viewport, clipped to [0, width].
  const double y0 = std::max(cy - rho, 0.0), y1 = std::min(cy + rho, view.height);
  if (!(y1 > y0)) return 0.0;
  constexpr int kStrips = 256;
  const double h = (y1 - y0) / kStrips;
  double area = 0.0;
  for (int i = 0; i < kStrips; ++i) {
    const double yy = y0 + (i + 0.5) * h - cy;
    const double w = std::sqrt(std::max(rho * rho - yy * yy, 0.0));
    area += std::max(std::min(cx + w, view.width) - std::max(cx - w, 0.0), 0.0) * h;
  }
  return area;
}

}  // namespace lodstream::schedule
