#include "schedule/path_gen.hpp"

#include <cmath>
#include <functional>

#include "core/error.hpp"

namespace lodstream::schedule {
namespace {

constexpr double kStep = 0.5;  // seconds between key frames where the pose moves

struct Frame {
  glm::vec3 c, up, a, b;
  float r;
  // Point at `along_a`, `along_b`, `height` (multiples of r) from c.
  glm::vec3 at(float along_a, float along_b, float height) const {
    return c + r * (along_a * a + along_b * b + height * up);
  }
};

Frame frame_of(const Bounds& bounds, glm::vec3 up) {
  if (bounds.empty()) throw Error("generated camera path: the scene's bounds are empty");
  if (!(glm::length(up) > 0.0f)) throw Error("generated camera path: the up vector is zero");
  Frame f;
  f.up = glm::normalize(up);
  f.c = bounds.center();
  f.r = std::max(0.5f * bounds.diagonal(), 1e-6f);
  // The world axis least aligned with up, made perpendicular to it.
  glm::vec3 axis(1.0f, 0.0f, 0.0f);
  for (glm::vec3 e : {glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)})
    if (std::abs(glm::dot(e, f.up)) < std::abs(glm::dot(axis, f.up))) axis = e;
  f.a = glm::normalize(axis - glm::dot(axis, f.up) * f.up);
  f.b = glm::cross(f.up, f.a);
  return f;
}

// Key frames every kStep over [t0, t1] of a pose moving with `pose(s)`, s in [0, 1].
void sample(std::vector<Keyframe>& out, double t0, double t1, glm::vec3 up,
            const std::function<std::pair<glm::vec3, glm::vec3>(float)>& pose) {
  const int steps = std::max(1, int(std::lround((t1 - t0) / kStep)));
  for (int i = out.empty() ? 0 : 1; i <= steps; ++i) {
    const double s = double(i) / double(steps);
    const auto [eye, target] = pose(float(s));
    out.push_back({t0 + (t1 - t0) * s, eye, target, up});
  }
}

}  // namespace

const std::vector<std::string>& generated_path_names() {
  static const std::vector<std::string> names{"orbit", "fly", "drive", "teleport"};
  return names;
}

CameraPath generate_path(const std::string& name, const Bounds& bounds, const PathGenOptions& options) {
  const Frame f = frame_of(bounds, options.up);
  std::vector<Keyframe> k;
  if (name == "orbit") {
    sample(k, 0.0, 12.0, f.up, [&](float s) {
      const float angle = 2.0f * float(M_PI) * s;
      return std::pair{f.at(1.8f * std::cos(angle), 1.8f * std::sin(angle), 0.4f), f.c};
    });
  } else if (name == "fly") {
    const float d = float(M_SQRT1_2);
    const glm::vec3 p0 = f.at(3.0f, 0.0f, 0.6f), p1 = f.at(1.2f * d, 1.2f * d, 0.3f),
                    p2 = f.at(0.0f, 0.6f, 0.15f);
    sample(k, 0.0, 6.0, f.up, [&](float s) { return std::pair{p0 + s * (p1 - p0), f.c}; });
    sample(k, 6.0, 12.0, f.up, [&](float s) { return std::pair{p1 + s * (p2 - p1), f.c}; });
  } else if (name == "drive") {
    sample(k, 0.0, 4.0, f.up, [&](float s) {
      const glm::vec3 eye = f.at(2.0f - 4.0f * s, 0.5f, 0.08f);
      return std::pair{eye, eye - f.r * f.a};
    });
  } else if (name == "teleport") {
    const glm::vec3 views[] = {f.at(1.5f, 0.0f, 0.3f), f.at(0.0f, 1.5f, 0.3f), f.at(-1.5f, 0.0f, 0.3f),
                               f.at(0.0f, -1.5f, 0.3f)};
    for (int i = 0; i < 4; ++i) {
      if (i > 0) k.push_back({3.0 * i + 0.001, views[i], f.c, f.up});
      k.push_back({3.0 * (i + 1), views[i], f.c, f.up});
    }
    k.insert(k.begin(), {0.0, views[0], f.c, f.up});
  } else {
    std::string known;
    for (const std::string& n : generated_path_names()) known += (known.empty() ? "gen:" : ", gen:") + n;
    throw Error("unknown generated camera path gen:" + name + " (known: " + known + ")");
  }
  return CameraPath(options.fov_y_degrees, options.width, options.height, std::move(k), "gen:" + name);
}

std::vector<double> teleports(const CameraPath& path, double max_jump_s) {
  std::vector<double> out;
  const auto& k = path.keyframes();
  for (size_t i = 0; i + 1 < k.size(); ++i)
    if (k[i + 1].t - k[i].t < max_jump_s) out.push_back(k[i + 1].t);
  return out;
}

}  // namespace lodstream::schedule
