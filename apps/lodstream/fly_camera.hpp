// Fly navigation for `view`'s window: mouse-look (drag with the left button: yaw about the world's up axis,
// pitch within +-89 degrees), W/S along the view direction, A/D sideways, E/Q along up, at a speed in world
// units per second (x4 while Shift is held; each scroll step multiplies it by 1.25). Pure computation.
#pragma once

#include <glm/glm.hpp>

#include "core/camera.hpp"
#include "render/context.hpp"

namespace lodstream::cli {

class FlyCamera {
 public:
  // Starts at `start`'s eye looking along start.target - start.eye; `up`: the world's up axis (not zero, not
  // parallel to the view direction); `speed` > 0.
  FlyCamera(const Camera& start, glm::vec3 up, float speed);

  // Applies `input` held for `dt_s` seconds: yaw and pitch by 0.003 radians per pixel of cursor motion, then
  // the motion of the keys held: eye += dt * speed * (x4 if fast) * normalize(sum of the held directions).
  void update(const render::WindowInput& input, double dt_s);

  // The camera now, for a width x height viewport (the start's field of view).
  Camera camera(int width, int height) const;
  float speed() const { return speed_; }

 private:
  glm::vec3 forward() const;

  glm::vec3 eye_, up_, a_, b_;  // a_, b_: horizontal axes (yaw 0 looks along a_, yaw pi/2 along b_)
  float yaw_ = 0.0f, pitch_ = 0.0f, speed_, fov_y_degrees_;
};

}  // namespace lodstream::cli
