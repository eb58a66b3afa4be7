// Camera: an explicit pinhole camera (eye, target, up, vertical field of view, image size), as DESIGN.md's
// camera file `{"eye": [x,y,z], "target": [x,y,z], "up": [0,1,0], "fov": 60, "size": [w,h]}` describes it.
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <string>

namespace lodstream {

struct Camera {
  glm::vec3 eye{0.0f, 0.0f, 1.0f};
  glm::vec3 target{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_y_degrees = 60.0f;  // vertical
  int width = 1280;
  int height = 720;

  glm::mat4 view() const;
  // OpenGL clip-space projection with the given depth range (0 < near < far).
  glm::mat4 projection(float near_plane, float far_plane) const;
  float aspect() const { return float(width) / float(height); }
};

// Parses a camera JSON file. Fields other than eye and target are optional and keep `defaults`' values.
// Throws lodstream::Error naming the file and the field on malformed input (degenerate eye == target,
// up parallel to the view direction, fov outside (0,180), size outside 1..16384).
Camera load_camera(const std::filesystem::path& file, const Camera& defaults = {});

// Checks a camera for the conditions load_camera() rejects; `where` names the source in the message.
void validate_camera(const Camera& camera, const std::string& where);

}  // namespace lodstream
