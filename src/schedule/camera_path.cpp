#include "schedule/camera_path.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.hpp"

namespace lodstream::schedule {

CameraPath::CameraPath(float fov_y_degrees, int width, int height, std::vector<Keyframe> keyframes,
                       const std::string& where)
    : fov_y_degrees_(fov_y_degrees), width_(width), height_(height), keyframes_(std::move(keyframes)) {
  if (!(fov_y_degrees_ > 0.0f && fov_y_degrees_ < 180.0f))
    throw Error(where + ": field 'fov' must be in (0, 180) degrees");
  if (width_ < 1 || height_ < 1 || width_ > 16384 || height_ > 16384)
    throw Error(where + ": field 'size' must be between 1x1 and 16384x16384");
  if (keyframes_.empty()) throw Error(where + ": a camera path needs at least one key frame");
  for (size_t i = 0; i < keyframes_.size(); ++i) {
    const Keyframe& k = keyframes_[i];
    const std::string at = where + ": keyframe " + std::to_string(i);
    if (!std::isfinite(k.t)) throw Error(at + ": 't' must be a finite number of seconds");
    if (i > 0 && !(k.t > keyframes_[i - 1].t))
      throw Error(at + ": 't' must be greater than the previous key frame's");
    validate_camera(Camera{k.eye, k.target, k.up, fov_y_degrees_, width_, height_}, at);
  }
}

size_t CameraPath::segment(double t) const {
  auto it = std::upper_bound(keyframes_.begin(), keyframes_.end(), t,
                             [](double value, const Keyframe& k) { return value < k.t; });
  return size_t(std::max<std::ptrdiff_t>(it - keyframes_.begin() - 1, 0));
}

Camera CameraPath::pose_at(double t) const {
  Camera c;
  c.fov_y_degrees = fov_y_degrees_;
  c.width = width_;
  c.height = height_;
  const size_t i = segment(t);
  const Keyframe& a = keyframes_[i];
  c.up = a.up;
  if (t <= a.t || i + 1 == keyframes_.size()) {
    c.eye = a.eye;
    c.target = a.target;
    return c;
  }
  const Keyframe& b = keyframes_[i + 1];
  const float s = float((t - a.t) / (b.t - a.t));
  c.eye = glm::mix(a.eye, b.eye, s);
  c.target = glm::mix(a.target, b.target, s);
  return c;
}

PoseVelocity CameraPath::velocity_at(double t) const {
  const size_t i = segment(t);
  if (t < keyframes_[i].t || i + 1 == keyframes_.size()) return {};
  const Keyframe& a = keyframes_[i];
  const Keyframe& b = keyframes_[i + 1];
  const float inv = float(1.0 / (b.t - a.t));
  return {(b.eye - a.eye) * inv, (b.target - a.target) * inv};
}

namespace {

glm::vec3 read_vec3(const nlohmann::json& j, const char* key, const std::string& at) {
  if (!j.contains(key)) throw Error(at + ": missing field '" + key + "'");
  const auto& v = j[key];
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
    throw Error(at + ": field '" + key + "' must be an array of three numbers");
  return {v[0].get<float>(), v[1].get<float>(), v[2].get<float>()};
}

}  // namespace

CameraPath parse_camera_path(const std::string& text, const std::string& where) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(where + ": invalid JSON at byte " + std::to_string(e.byte));
  }
  if (!j.is_object()) throw Error(where + ": a camera path must be a JSON object");
  Camera defaults;
  float fov = defaults.fov_y_degrees;
  int width = defaults.width, height = defaults.height;
  if (j.contains("fov")) {
    if (!j["fov"].is_number()) throw Error(where + ": field 'fov' must be a number (degrees)");
    fov = j["fov"].get<float>();
  }
  if (j.contains("size")) {
    const auto& s = j["size"];
    if (!s.is_array() || s.size() != 2 || !s[0].is_number_integer() || !s[1].is_number_integer())
      throw Error(where + ": field 'size' must be [width, height] in pixels");
    width = s[0].get<int>();
    height = s[1].get<int>();
  }
  if (!j.contains("keyframes") || !j["keyframes"].is_array())
    throw Error(where + ": field 'keyframes' must be an array of key frames");
  std::vector<Keyframe> keys;
  for (size_t i = 0; i < j["keyframes"].size(); ++i) {
    const auto& k = j["keyframes"][i];
    const std::string at = where + ": keyframe " + std::to_string(i);
    if (!k.is_object()) throw Error(at + ": a key frame must be a JSON object");
    if (!k.contains("t") || !k["t"].is_number()) throw Error(at + ": field 't' must be a number (seconds)");
    Keyframe key;
    key.t = k["t"].get<double>();
    key.eye = read_vec3(k, "eye", at);
    key.target = read_vec3(k, "target", at);
    if (k.contains("up")) key.up = read_vec3(k, "up", at);
    keys.push_back(key);
  }
  return CameraPath(fov, width, height, std::move(keys), where);
}

CameraPath load_camera_path(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file.string() + ": cannot open camera path file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_camera_path(text.str(), file.string());
}

}  // namespace lodstream::schedule
