#include "schedule/screen_area.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lodstream::schedule {

namespace {

// Area of {0 <= x <= a, 0 <= y <= b} inside the disc of radius r about the origin (a, b >= 0): the box
// [0, x0] x [0, b] under the arc, x0 = sqrt(r^2 - b^2) where the arc crosses y = b, plus the integral of the
// arc from x0 to a, int sqrt(r^2 - x^2) dx = (x sqrt(r^2 - x^2) + r^2 asin(x / r)) / 2.
double quadrant_area(double a, double b, double r) {
  a = std::min(a, r), b = std::min(b, r);
  if (a * a + b * b <= r * r) return a * b;
  auto arc_integral = [r](double x) {
    return 0.5 * (x * std::sqrt(std::max(r * r - x * x, 0.0)) + r * r * std::asin(std::min(x / r, 1.0)));
  };
  const double x0 = std::sqrt(r * r - b * b);
  return x0 * b + arc_integral(a) - arc_integral(x0);
}

// quadrant_area of the box between the origin and the corner (x, y), signed by the quadrant (negative in the
// second and fourth), so that a rectangle's area inside the disc is the alternating sum over its corners.
double corner_area(double x, double y, double r) {
  const double area = quadrant_area(std::abs(x), std::abs(y), r);
  return (x < 0.0) != (y < 0.0) ? -area : area;
}

}  // namespace

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
  // The viewport [0, width] x [0, height] inside the disc, by its corners relative to the disc's centre.
  const double x0 = -cx, x1 = view.width - cx, y0 = -cy, y1 = view.height - cy;
  const double area = corner_area(x1, y1, rho) - corner_area(x0, y1, rho) - corner_area(x1, y0, rho) +
                      corner_area(x0, y0, rho);
  return std::max(area, 0.0);
}

}  // namespace lodstream::schedule
