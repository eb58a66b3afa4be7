#include "schedule/motion.hpp"

#include <cmath>

namespace lodstream::schedule {

namespace {

// Rodrigues' rotation of v by |w| radians about w / |w|.
glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& w) {
  const double angle = glm::length(w);
  if (angle == 0.0) return v;
  const glm::dvec3 k = w / angle;
  const double c = std::cos(angle), s = std::sin(angle);
  return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1.0 - c);
}

}  // namespace

View view_of(const ViewSample& sample) {
  View v;
  v.eye = sample.eye;
  v.forward = glm::normalize(sample.forward);
  v.right = glm::normalize(glm::cross(v.forward, sample.up));
  v.up = glm::cross(v.right, v.forward);
  v.width = sample.width;
  v.height = sample.height;
  v.tan_half_y = std::tan(0.5 * sample.fov_y_radians);
  v.tan_half_x = v.tan_half_y * v.width / v.height;
  return v;
}

ViewSample predict(const ViewSample& sample, double horizon_s) {
  ViewSample p = sample;
  p.time_s = sample.time_s + horizon_s;
  p.eye = sample.eye + sample.velocity * horizon_s;
  const glm::dvec3 turn = sample.angular_velocity * horizon_s;
  p.forward = glm::normalize(rotate(sample.forward, turn));
  p.up = glm::normalize(rotate(sample.up, turn));
  return p;
}

std::vector<WeightedView> predicted_views(const ViewSample& sample, double lead_s,
                                          const PredictionHorizons& horizons) {
  const bool still = sample.velocity == glm::dvec3(0.0) && sample.angular_velocity == glm::dvec3(0.0);
  std::vector<WeightedView> views;
  for (double h : horizons.horizons_s) {
    views.push_back({view_of(predict(sample, lead_s + h)), std::exp(-h / horizons.decay_s), h});
    if (still) {
      views.back().weight = 1.0;
      break;
    }
  }
  return views;
}

}  // namespace lodstream::schedule
