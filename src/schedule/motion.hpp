// Motion prediction (DESIGN.md, Client runtime and Serving and the wire; seed 001 §6 dead reckoning, seed 003
// §4 motion modes): the client reports its pose with linear and angular velocity, and the scheduler asks
// where the camera will be `horizon` seconds later. The model is first-order dead reckoning (DIS IEEE 1278's
// "uniform linear motion", plus a uniform rotation):
//   eye(t + h)     = eye + velocity * h
//   forward(t + h) = R(angular_velocity * h) forward,   up(t + h) = R(angular_velocity * h) up,
// R(w) the rotation by |w| radians about w / |w| (Rodrigues' formula). A still camera (both velocities zero)
// predicts itself, which is seed 003's STANDING mode; TURNING and STRAIGHT are the two velocities alone.
// Pure computation, O(1).
#pragma once

#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "schedule/screen_error.hpp"

namespace lodstream::schedule {

// What a ViewUpdate carries: the pose at `time_s` and its motion.
struct ViewSample {
  double time_s = 0.0;
  glm::dvec3 eye{0.0};
  glm::dvec3 forward{0.0, 0.0, -1.0};  // unit view direction
  glm::dvec3 up{0.0, 1.0, 0.0};        // not parallel to forward
  glm::dvec3 velocity{0.0};            // of the eye, world units per second
  glm::dvec3 angular_velocity{0.0};    // axis * rate (radians per second), world space
  double fov_y_radians = 1.0471975511965976;
  double width = 1280.0, height = 720.0;  // viewport, pixels
};

// The View (orthonormal basis, pinhole scale) of a sample's pose.
View view_of(const ViewSample& sample);

// The sample's pose `horizon_s` seconds later under constant linear and angular velocity (the formulas
// above); the viewport and field of view are kept.
ViewSample predict(const ViewSample& sample, double horizon_s);

// A view with the weight the scheduler gives it (seed 003's benefit integrated along the predicted path,
// sampled at a few horizons).
struct WeightedView {
  View view;
  double weight = 1.0;
  double horizon_s = 0.0;
};

// Horizons and weights at which the scheduler looks ahead: 0, 0.25, 0.5, 1 and 2 s, weights
// exp(-horizon / 1 s) (nearer futures are more certain and come sooner).
struct PredictionHorizons {
  std::vector<double> horizons_s{0.0, 0.25, 0.5, 1.0, 2.0};
  double decay_s = 1.0;
};

// The weighted views of `sample` predicted `lead_s` + each horizon ahead (lead_s: how far the present is
// already past the sample, e.g. the time since it was taken plus the one-way delay of what is sent now).
// A still camera gives one view of weight 1 (its predictions coincide).
std::vector<WeightedView> predicted_views(const ViewSample& sample, double lead_s,
                                          const PredictionHorizons& horizons = {});

}  // namespace lodstream::schedule
