// End-to-end tests of `lodstream measure` (models and --images).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/image.hpp"
#include "support/run.hpp"
#include "support/shapes.hpp"

using namespace lodstream;

namespace {
// Writes `mesh` as a Wavefront OBJ (positions and triangles only).
std::filesystem::path write_obj(const Mesh& mesh, const std::string& name) {
  auto path = test::temp_dir() / name;
  std::ofstream out(path);
  for (const glm::vec3& p : mesh.positions) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
  for (size_t i = 0; i < mesh.indices.size(); i += 3)
    out << "f " << mesh.indices[i] + 1 << ' ' << mesh.indices[i + 1] + 1 << ' ' << mesh.indices[i + 2] + 1
        << '\n';
  return path;
}

std::filesystem::path write_gray_png(int w, int h, uint8_t value, const std::string& name) {
  Image img(w, h);
  for (size_t i = 0; i < img.rgba.size(); i += 4) {
    img.rgba[i] = img.rgba[i + 1] = img.rgba[i + 2] = value;
    img.rgba[i + 3] = 255;
  }
  auto path = test::temp_dir() / name;
  save_png(img, path);
  return path;
}

// A failed run: exit status 1 and exactly one line "lodstream: error: ..." that mentions `needle`.
void expect_one_line_error(const test::RunResult& r, const std::string& needle) {
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.rfind("lodstream: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
}
}  // namespace

TEST(CliMeasure, ShiftedPlaneJson) {
  const double d = 0.125;  // exact in binary and in the OBJ's decimal text
  auto a = write_obj(test::grid(8, 0.0f), "plane.obj");
  auto b = write_obj(test::grid(5, float(d)), "shifted.obj");
  auto r = test::run_lodstream({"measure", a.string(), b.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = r.json();
  for (const char* key : {"hausdorff", "mean", "rms", "a_to_b_max", "b_to_a_max"})
    EXPECT_NEAR(j[key].get<double>(), d, 1e-6) << key;
  EXPECT_NEAR(j["diagonal"].get<double>(), std::sqrt(2.0), 1e-6);  // B covers [0,1]^2 in a plane
  EXPECT_NEAR(j["hausdorff_relative"].get<double>(), d / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(j["mean_relative"].get<double>(), d / std::sqrt(2.0), 1e-6);
  EXPECT_GE(j["samples"].get<size_t>(), 200000u);  // at least the default 100,000 area samples a side
  EXPECT_GE(j["time_s"].get<double>(), 0.0);
}

TEST(CliMeasure, SamplesOptionAndPlainOutput) {
  auto a = write_obj(test::sphere(1.0f, 12, 24), "sphere.obj");
  auto r = test::run_lodstream({"measure", a.string(), a.string(), "--samples", "1000", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = r.json();
  EXPECT_LT(j["hausdorff"].get<double>(), 1e-6);
  // Each side: 266 vertices plus about 1000 area samples (at least one in each of the 528 triangles).
  EXPECT_GE(j["samples"].get<size_t>(), 2u * (266 + 1000));
  EXPECT_LE(j["samples"].get<size_t>(), 2u * (266 + 1000 + 528));
  auto plain = test::run_lodstream({"measure", a.string(), a.string()});
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_NE(plain.out.find("hausdorff"), std::string::npos) << plain.out;
}

TEST(CliMeasure, RealModelAgainstItself) {
  auto elephant = test::data_file("elephant.off");
  auto r = test::run_lodstream({"measure", elephant.string(), elephant.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(r.json()["hausdorff_relative"].get<double>(), 1e-6);
}

TEST(CliMeasure, Images) {
  auto a = write_gray_png(16, 12, 100, "a.png");
  auto b = write_gray_png(16, 12, 110, "b.png");
  auto r = test::run_lodstream({"measure", "--images", a.string(), b.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = r.json();
  // Constant offset 10: PSNR = 10·log10(255²/10²) = 28.1308 dB; constant images: SSIM = (2ab + C1)/(a² + b² +
  // C1) with a = 100, b = 110, C1 = (0.01·255)² = 6.5025: 22006.5025 / 22106.5025 = 0.9954765.
  EXPECT_NEAR(j["psnr"].get<double>(), 28.1308036, 1e-6);
  EXPECT_NEAR(j["ssim"].get<double>(), 0.9954765, 1e-6);
  auto same = test::run_lodstream({"measure", "--images", a.string(), a.string(), "--json"});
  ASSERT_EQ(same.status, 0) << same.err;
  EXPECT_TRUE(same.json()["psnr"].is_null());
  EXPECT_DOUBLE_EQ(same.json()["ssim"].get<double>(), 1.0);
}

TEST(CliMeasure, BadInput) {
  auto plane = write_obj(test::grid(2), "small.obj");
  auto missing = (test::temp_dir() / "missing.obj").string();
  expect_one_line_error(test::run_lodstream({"measure", plane.string(), missing}), "missing.obj");
  Mesh points_only = test::grid(2);
  points_only.indices.clear();
  auto empty = write_obj(points_only, "empty.obj");
  expect_one_line_error(test::run_lodstream({"measure", empty.string(), plane.string()}), "empty.obj");

  auto small = write_gray_png(16, 12, 100, "small.png");
  auto large = write_gray_png(16, 13, 100, "large.png");
  expect_one_line_error(test::run_lodstream({"measure", "--images", small.string(), large.string()}),
                        "16x13");
  expect_one_line_error(test::run_lodstream({"measure", "--images", small.string(), missing}), "missing.obj");
  auto r = test::run_lodstream({"measure", "--images", small.string(), small.string(), "--samples", "10"});
  expect_one_line_error(r, "--samples");
  EXPECT_NE(test::run_lodstream({"measure", plane.string()}).status, 0);
}
