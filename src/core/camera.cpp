#include "core/camera.hpp"

#include <cmath>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "core/error.hpp"

namespace lodstream {

glm::mat4 Camera::view() const {
  return glm::lookAt(eye, target, up);
}

glm::mat4 Camera::projection(float near_plane, float far_plane) const {
  return glm::perspective(glm::radians(fov_y_degrees), aspect(), near_plane, far_plane);
}

void validate_camera(const Camera& c, const std::string& where) {
  auto finite = [](glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (!finite(c.eye) || !finite(c.target) || !finite(c.up))
    throw Error(where + ": camera has a non-finite coordinate");
  glm::vec3 dir = c.target - c.eye;
  if (glm::length(dir) <= 0.0f) throw Error(where + ": camera eye and target are the same point");
  if (glm::length(glm::cross(glm::normalize(dir), c.up)) < 1e-6f)
    throw Error(where + ": camera up is parallel to the view direction (or zero)");
  if (!(c.fov_y_degrees > 0.0f && c.fov_y_degrees < 180.0f))
    throw Error(where + ": camera fov must be in (0, 180) degrees");
  if (c.width < 1 || c.height < 1 || c.width > 16384 || c.height > 16384)
    throw Error(where + ": camera size must be between 1x1 and 16384x16384");
}

namespace {

glm::vec3 read_vec3(const nlohmann::json& j, const char* key, const std::string& where) {
  const auto& v = j.at(key);
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
    throw Error(where + ": field '" + key + "' must be an array of three numbers");
  return {v[0].get<float>(), v[1].get<float>(), v[2].get<float>()};
}

}  // namespace

Camera load_camera(const std::filesystem::path& file, const Camera& defaults) {
  const std::string where = file.string();
  std::ifstream in(file);
  if (!in) throw Error(where + ": cannot open camera file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(where + ": invalid JSON at byte " + std::to_string(e.byte));
  }
  if (!j.is_object()) throw Error(where + ": a camera must be a JSON object");
  Camera c = defaults;
  for (const char* key : {"eye", "target"})
    if (!j.contains(key)) throw Error(where + ": missing field '" + key + "'");
  c.eye = read_vec3(j, "eye", where);
  c.target = read_vec3(j, "target", where);
  if (j.contains("up")) c.up = read_vec3(j, "up", where);
  if (j.contains("fov")) {
    if (!j["fov"].is_number()) throw Error(where + ": field 'fov' must be a number (degrees)");
    c.fov_y_degrees = j["fov"].get<float>();
  }
  if (j.contains("size")) {
    const auto& s = j["size"];
    if (!s.is_array() || s.size() != 2 || !s[0].is_number_integer() || !s[1].is_number_integer())
      throw Error(where + ": field 'size' must be [width, height] in pixels");
    c.width = s[0].get<int>();
    c.height = s[1].get<int>();
  }
  validate_camera(c, where);
  return c;
}

}  // namespace lodstream
