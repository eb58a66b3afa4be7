#include "schedule/screen_error.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream::schedule {

View View::of(const Camera& camera) {
  View v;
  v.eye = glm::dvec3(camera.eye);
  v.forward = glm::normalize(glm::dvec3(camera.target) - v.eye);
  v.right = glm::normalize(glm::cross(v.forward, glm::dvec3(camera.up)));
  v.up = glm::cross(v.right, v.forward);
  v.width = camera.width;
  v.height = camera.height;
  v.tan_half_y = std::tan(0.5 * glm::radians(double(camera.fov_y_degrees)));
  v.tan_half_x = v.tan_half_y * v.width / v.height;
  return v;
}

double max_scale(const glm::mat4& m) {
  const glm::dmat3 linear(m);
  return std::max({glm::length(linear[0]), glm::length(linear[1]), glm::length(linear[2])});
}

WorldSphere to_world(const Sphere& sphere, const glm::mat4& transform, double scale) {
  const glm::dvec4 c = glm::dmat4(transform) * glm::dvec4(glm::dvec3(sphere.center), 1.0);
  return {glm::dvec3(c), double(sphere.radius) * scale};
}

double sphere_distance(const WorldSphere& sphere, const View& view) {
  return std::max(glm::length(sphere.center - view.eye) - sphere.radius, view.min_distance);
}

double screen_error(double world_error, const WorldSphere& sphere, const View& view) {
  if (std::isinf(world_error)) return INFINITY;
  return world_error * view.focal_pixels() / sphere_distance(sphere, view);
}

bool in_frustum(const WorldSphere& sphere, const View& view) {
  // Camera-space centre (x right, y up, z forward); inward plane normals (1, 0, tx), (-1, 0, tx),
  // (0, 1, ty), (0, -1, ty), (0, 0, 1), all through the eye.
  const glm::dvec3 d = sphere.center - view.eye;
  const double x = glm::dot(d, view.right), y = glm::dot(d, view.up), z = glm::dot(d, view.forward);
  const double r = sphere.radius;
  if (z < -r) return false;
  const double nx = std::sqrt(1.0 + view.tan_half_x * view.tan_half_x);
  const double ny = std::sqrt(1.0 + view.tan_half_y * view.tan_half_y);
  return (z * view.tan_half_x - std::abs(x)) / nx >= -r && (z * view.tan_half_y - std::abs(y)) / ny >= -r;
}

}  // namespace lodstream::schedule
