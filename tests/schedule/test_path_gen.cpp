#include <gtest/gtest.h>

#include "core/error.hpp"
#include "schedule/path_gen.hpp"

using namespace lodstream;
using namespace lodstream::schedule;

namespace {

Bounds box(glm::vec3 lo, glm::vec3 hi) {
  Bounds b;
  b.add(lo);
  b.add(hi);
  return b;
}

}  // namespace

// Every generated path is fitted to the bounds: orbit, fly and teleport look at the centre; distances and
// heights are the documented multiples of r (half the diagonal) along the given up axis.
TEST(PathGen, PathsAreFittedToTheBounds) {
  const Bounds b = box({10.0f, -2.0f, 0.0f}, {14.0f, 2.0f, 3.0f});  // z up, like OpenFOAM's models
  const glm::vec3 c = b.center();
  const float r = 0.5f * b.diagonal();
  PathGenOptions options;
  options.up = {0.0f, 0.0f, 1.0f};
  for (const std::string& name : generated_path_names()) {
    const CameraPath path = generate_path(name, b, options);
    EXPECT_EQ(path.start(), 0.0) << name;
    EXPECT_GE(path.end(), 4.0) << name;
    for (double t = 0.0; t <= path.end(); t += 0.25) {
      const Camera cam = path.pose_at(t);
      EXPECT_EQ(cam.up, options.up) << name;
      const float height = cam.eye.z - c.z;
      EXPECT_GT(height, 0.0f) << name << " t=" << t;  // above the centre
      EXPECT_LE(height, 0.6f * r + 1e-4f) << name << " t=" << t;
      if (name != "drive") {
        EXPECT_LT(glm::length(cam.target - c), 1e-4f) << name;
      }
    }
  }
  const CameraPath orbit = generate_path("orbit", b, options);
  for (double t = 0.0; t <= orbit.end(); t += 0.5) {
    const glm::vec3 d = orbit.pose_at(t).eye - c;
    EXPECT_NEAR(glm::length(glm::vec2(d.x, d.y)), 1.8f * r, 1e-3f * r);
  }
  // fly enters: from 3 r out to 0.6 r from the centre (horizontally).
  const CameraPath fly = generate_path("fly", b, options);
  auto horizontal = [&](const CameraPath& p, double t) {
    const glm::vec3 d = p.pose_at(t).eye - c;
    return glm::length(glm::vec2(d.x, d.y));
  };
  EXPECT_NEAR(horizontal(fly, 0.0), 3.0f * r, 1e-3f * r);
  EXPECT_NEAR(horizontal(fly, fly.end()), 0.6f * r, 1e-3f * r);
  // drive crosses 4 r in 4 s: faster than the fly.
  const CameraPath drive = generate_path("drive", b, options);
  EXPECT_NEAR(glm::length(drive.pose_at(drive.end()).eye - drive.pose_at(0.0).eye) / drive.end(), r,
              1e-3f * r);
}

TEST(PathGen, TeleportsAreFound) {
  const Bounds b = box({-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f});
  const CameraPath path = generate_path("teleport", b);
  const std::vector<double> jumps = teleports(path);
  ASSERT_EQ(jumps.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(jumps[i], 3.0 * double(i + 1), 0.01);
    // a distant view: the eye moves by more than r within the jump
    EXPECT_GT(glm::length(path.pose_at(jumps[i]).eye - path.pose_at(jumps[i] - 0.002).eye), 1.0f);
  }
  EXPECT_TRUE(teleports(generate_path("orbit", b)).empty());
}

TEST(PathGen, BadInputIsAnError) {
  const Bounds b = box({-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f});
  EXPECT_THROW(generate_path("spiral", b), Error);
  EXPECT_THROW(generate_path("orbit", Bounds{}), Error);
  PathGenOptions zero;
  zero.up = glm::vec3(0.0f);
  EXPECT_THROW(generate_path("fly", b, zero), Error);
}
