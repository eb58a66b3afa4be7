#include "fly_camera.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream::cli {

namespace {
constexpr float kRadiansPerPixel = 0.003f;
constexpr float kMaxPitch = glm::radians(89.0f);
constexpr float kFastFactor = 4.0f;
constexpr float kScrollFactor = 1.25f;
}  // namespace

FlyCamera::FlyCamera(const Camera& start, glm::vec3 up, float speed)
    : eye_(start.eye), up_(glm::normalize(up)), speed_(speed), fov_y_degrees_(start.fov_y_degrees) {
  // a_: the world axis least aligned with up, made perpendicular to it; b_ = up x a_.
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(up_[i]) < std::abs(up_[k])) k = i;
  glm::vec3 axis(0.0f);
  axis[k] = 1.0f;
  a_ = glm::normalize(axis - up_ * glm::dot(axis, up_));
  b_ = glm::cross(up_, a_);
  const glm::vec3 f = glm::normalize(start.target - start.eye);
  pitch_ = std::clamp(std::asin(std::clamp(glm::dot(f, up_), -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
  yaw_ = std::atan2(glm::dot(f, b_), glm::dot(f, a_));
}

glm::vec3 FlyCamera::forward() const {
  return std::cos(pitch_) * (std::cos(yaw_) * a_ + std::sin(yaw_) * b_) + std::sin(pitch_) * up_;
}

void FlyCamera::update(const render::WindowInput& input, double dt_s) {
  // Yaw grows from a_ towards b_ = up x a_, a turn to the left: the cursor moving right turns right.
  yaw_ -= kRadiansPerPixel * float(input.look_x);
  pitch_ = std::clamp(pitch_ - kRadiansPerPixel * float(input.look_y), -kMaxPitch, kMaxPitch);
  speed_ *= std::pow(kScrollFactor, float(input.scroll));
  const glm::vec3 f = forward(), right = glm::normalize(glm::cross(f, up_));
  glm::vec3 move(0.0f);
  if (input.forward) move += f;
  if (input.back) move -= f;
  if (input.right) move += right;
  if (input.left) move -= right;
  if (input.up) move += up_;
  if (input.down) move -= up_;
  if (glm::length(move) > 0.0f)
    eye_ += glm::normalize(move) * float(dt_s) * speed_ * (input.fast ? kFastFactor : 1.0f);
}

Camera FlyCamera::camera(int width, int height) const {
  Camera c;
  c.eye = eye_;
  c.target = eye_ + forward();
  c.up = up_;
  c.fov_y_degrees = fov_y_degrees_;
  c.width = width;
  c.height = height;
  return c;
}

}  // namespace lodstream::cli
