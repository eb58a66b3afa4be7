#include "view_motion.hpp"

#include <cmath>

#include "schedule/screen_error.hpp"

namespace lodstream::cli {

schedule::ViewSample view_sample(const Camera& camera, double time_s, const Camera& from, const Camera& to,
                                 double dt_s) {
  const schedule::View v = schedule::View::of(camera);
  schedule::ViewSample s;
  s.time_s = time_s;
  s.eye = v.eye;
  s.forward = v.forward;
  s.up = v.up;
  s.fov_y_radians = glm::radians(double(camera.fov_y_degrees));
  s.width = camera.width;
  s.height = camera.height;
  s.velocity = (glm::dvec3(to.eye) - glm::dvec3(from.eye)) / dt_s;
  const glm::dvec3 a = schedule::View::of(from).forward, b = schedule::View::of(to).forward;
  const glm::dvec3 axis = glm::cross(a, b);
  const double sine = glm::length(axis);
  if (sine > 1e-12) s.angular_velocity = axis / sine * std::atan2(sine, glm::dot(a, b)) / dt_s;
  return s;
}

wire::ViewUpdate view_update(const schedule::ViewSample& s) {
  wire::ViewUpdate u;
  u.client_time_s = s.time_s;
  u.eye = glm::vec3(s.eye);
  u.forward = glm::vec3(s.forward);
  u.up = glm::vec3(s.up);
  u.velocity = glm::vec3(s.velocity);
  u.angular_velocity = glm::vec3(s.angular_velocity);
  u.fov_y_radians = float(s.fov_y_radians);
  u.viewport_width = uint16_t(s.width);
  u.viewport_height = uint16_t(s.height);
  return u;
}

}  // namespace lodstream::cli
