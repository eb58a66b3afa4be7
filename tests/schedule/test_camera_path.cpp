#include <gtest/gtest.h>

#include <fstream>

#include "core/error.hpp"
#include "schedule/camera_path.hpp"
#include "support/run.hpp"

using namespace lodstream;
using schedule::parse_camera_path;

namespace {

const char* kPath = R"({"fov": 45, "size": [640, 480], "keyframes": [
  {"t": 0, "eye": [0, 0, 10], "target": [0, 0, 0]},
  {"t": 2, "eye": [4, 0, 10], "target": [2, 0, 0], "up": [0, 1, 0]},
  {"t": 3, "eye": [4, 3, 10], "target": [2, 0, 0], "up": [0, 0, 1]}]})";

std::string error_of(const std::string& text) {
  try {
    parse_camera_path(text, "p.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(CameraPath, InterpolatesEyeAndTargetLinearlyAndClamps) {
  auto path = parse_camera_path(kPath, "p.json");
  EXPECT_EQ(path.width(), 640);
  EXPECT_EQ(path.height(), 480);
  EXPECT_FLOAT_EQ(path.fov_y_degrees(), 45.0f);
  EXPECT_DOUBLE_EQ(path.end(), 3.0);
  Camera c = path.pose_at(0.5);
  EXPECT_FLOAT_EQ(c.eye.x, 1.0f);
  EXPECT_FLOAT_EQ(c.target.x, 0.5f);
  EXPECT_EQ(c.width, 640);
  EXPECT_FLOAT_EQ(c.fov_y_degrees, 45.0f);
  c = path.pose_at(2.5);
  EXPECT_FLOAT_EQ(c.eye.y, 1.5f);
  EXPECT_FLOAT_EQ(c.eye.x, 4.0f);
  EXPECT_EQ(c.up, glm::vec3(0, 1, 0));  // up of the key frame at or before t
  c = path.pose_at(100.0);              // held after the last key frame
  EXPECT_EQ(c.eye, glm::vec3(4, 3, 10));
  EXPECT_EQ(c.up, glm::vec3(0, 0, 1));
  c = path.pose_at(-1.0);  // and before the first
  EXPECT_EQ(c.eye, glm::vec3(0, 0, 10));
}

TEST(CameraPath, VelocityIsTheSegmentSlopeAndZeroOutside) {
  auto path = parse_camera_path(kPath, "p.json");
  auto v = path.velocity_at(1.0);
  EXPECT_FLOAT_EQ(v.eye.x, 2.0f);
  EXPECT_FLOAT_EQ(v.target.x, 1.0f);
  v = path.velocity_at(2.0);  // the later segment at a key frame
  EXPECT_FLOAT_EQ(v.eye.x, 0.0f);
  EXPECT_FLOAT_EQ(v.eye.y, 3.0f);
  EXPECT_EQ(path.velocity_at(3.0).eye, glm::vec3(0.0f));
  EXPECT_EQ(path.velocity_at(-0.5).eye, glm::vec3(0.0f));
}

TEST(CameraPath, DefaultsAndLoadFromFile) {
  auto file = test::temp_dir() / "path.json";
  std::ofstream(file) << R"({"keyframes": [{"t": 1, "eye": [1, 2, 3], "target": [0, 0, 0]}]})";
  auto path = schedule::load_camera_path(file);
  EXPECT_FLOAT_EQ(path.fov_y_degrees(), 60.0f);
  EXPECT_EQ(path.width(), 1280);
  EXPECT_EQ(path.pose_at(0.0).eye, glm::vec3(1, 2, 3));
  EXPECT_EQ(path.pose_at(0.0).up, glm::vec3(0, 1, 0));
  EXPECT_THROW(schedule::load_camera_path(test::temp_dir() / "missing.json"), Error);
}

TEST(CameraPath, RejectsBadInputWithOneLineNamingFileAndKeyframe) {
  EXPECT_EQ(error_of("{"), "p.json: invalid JSON at byte 2");
  EXPECT_EQ(error_of("[]"), "p.json: a camera path must be a JSON object");
  EXPECT_EQ(error_of(R"({"keyframes": []})"), "p.json: a camera path needs at least one key frame");
  EXPECT_EQ(error_of(R"({"fov": 0, "keyframes": []})"), "p.json: field 'fov' must be in (0, 180) degrees");
  EXPECT_EQ(error_of(R"({"size": [1], "keyframes": []})"),
            "p.json: field 'size' must be [width, height] in pixels");
  const std::string one = R"({"t": 0, "eye": [0, 0, 1], "target": [0, 0, 0]})";
  EXPECT_EQ(error_of(R"({"keyframes": [)" + one + R"(, {"t": 0, "eye": [0, 0, 1], "target": [0, 0, 0]}]})"),
            "p.json: keyframe 1: 't' must be greater than the previous key frame's");
  EXPECT_EQ(error_of(R"({"keyframes": [)" + one + R"(, {"t": 1, "eye": [0, 0, 1]}]})"),
            "p.json: keyframe 1: missing field 'target'");
  EXPECT_EQ(error_of(R"({"keyframes": [{"t": 0, "eye": [0, 0, 1], "target": [0, 0, "x"]}]})"),
            "p.json: keyframe 0: field 'target' must be an array of three numbers");
  EXPECT_EQ(error_of(R"({"keyframes": [{"t": 0, "eye": [0, 0, 1], "target": [0, 0, 1]}]})"),
            "p.json: keyframe 0: camera eye and target are the same point");
  EXPECT_EQ(error_of(R"({"keyframes": [{"t": 0, "eye": [0, 1, 0], "target": [0, 0, 0]}]})"),
            "p.json: keyframe 0: camera up is parallel to the view direction (or zero)");
  EXPECT_EQ(error_of(R"({"keyframes": [{"eye": [0, 1, 0], "target": [0, 0, 0]}]})"),
            "p.json: keyframe 0: field 't' must be a number (seconds)");
}
