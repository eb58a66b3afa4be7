// Camera paths (DESIGN.md, Addresses and paths): `{"fov": 60, "size": [1280, 720], "keyframes": [{"t": 0.0,
// "eye": [x,y,z], "target": [x,y,z], "up": [0,1,0]}, ...]}`. Eye and target are interpolated linearly between
// key frames; the pose is held (clamped) before the first and after the last key frame; `up` defaults to +Y
// and is taken from the key frame at or before t (it is not interpolated). Pure computation after loading.
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "core/camera.hpp"

namespace lodstream::schedule {

struct Keyframe {
  double t = 0.0;  // seconds
  glm::vec3 eye{0.0f, 0.0f, 1.0f};
  glm::vec3 target{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
};

// Linear velocities of the eye and target (world units per second).
struct PoseVelocity {
  glm::vec3 eye{0.0f};
  glm::vec3 target{0.0f};
};

class CameraPath {
 public:
  // Validates like load_camera_path (key frames sorted by strictly increasing t, at least one, each a valid
  // camera with `fov` and `size`); `where` names the source in error messages.
  CameraPath(float fov_y_degrees, int width, int height, std::vector<Keyframe> keyframes,
             const std::string& where = "camera path");

  const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  double start() const { return keyframes_.front().t; }
  double end() const { return keyframes_.back().t; }
  float fov_y_degrees() const { return fov_y_degrees_; }
  int width() const { return width_; }
  int height() const { return height_; }

  // The camera at time t: eye and target interpolated linearly between the key frames around t, clamped to
  // the first / last key frame outside [start, end]. Cost: O(log keyframes).
  Camera pose_at(double t) const;
  // d(eye)/dt and d(target)/dt at t: the slope of the segment holding t (the later segment at a key frame),
  // zero outside [start, end). Cost: O(log keyframes).
  PoseVelocity velocity_at(double t) const;

 private:
  size_t segment(double t) const;  // index i with keyframes_[i].t <= t < keyframes_[i + 1].t

  float fov_y_degrees_;
  int width_, height_;
  std::vector<Keyframe> keyframes_;
};

// Parses a camera path file. Throws lodstream::Error with one line naming the file (and the key frame, by
// index, when one is at fault): unreadable file, invalid JSON, missing or mistyped field, no key frames,
// times not strictly increasing or not finite, a key frame that is not a valid camera (eye == target, up
// parallel to the view direction), fov outside (0, 180), size outside 1..16384.
CameraPath load_camera_path(const std::filesystem::path& file);
// The same from JSON text; `where` names the source.
CameraPath parse_camera_path(const std::string& text, const std::string& where);

}  // namespace lodstream::schedule
