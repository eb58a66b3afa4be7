// `lodstream render` end to end: images from explicit cameras, determinism, JSON, and every kind of bad
// input.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "core/image.hpp"
#include "support/run.hpp"
#include "support/shapes.hpp"

using namespace lodstream;

namespace {

// A sphere of radius 1 at the origin written as an OBJ file.
std::filesystem::path sphere_obj() {
  static const std::filesystem::path file = [] {
    auto p = test::temp_dir() / "sphere.obj";
    Mesh m = test::sphere(1.0f, 16, 32);
    std::ofstream out(p);
    for (auto& v : m.positions) out << "v " << v.x << ' ' << v.y << ' ' << v.z << '\n';
    for (size_t i = 0; i < m.indices.size(); i += 3)
      out << "f " << m.indices[i] + 1 << ' ' << m.indices[i + 1] + 1 << ' ' << m.indices[i + 2] + 1 << '\n';
    return p;
  }();
  return file;
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Bad input: exit status 1, one line on standard error that starts with "lodstream: error:" and names `what`.
void expect_error(const std::vector<std::string>& args, const std::string& what) {
  auto r = test::run_lodstream(args);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.rfind("lodstream: error:", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(what), std::string::npos) << "expected '" << what << "' in: " << r.err;
}

}  // namespace

TEST(CliRender, DrawsTheModelAndReportsJson) {
  auto out = test::temp_dir() / "sphere.png";
  auto r = test::run_lodstream({"render", sphere_obj().string(), "--eye", "0,0,4", "--target", "0,0,0",
                                "--size", "64x48", "--frames", "3", "-o", out.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = r.json();
  EXPECT_EQ(j["triangles"], 2 * 32 * 15);
  EXPECT_EQ(j["width"], 64);
  EXPECT_EQ(j["height"], 48);
  EXPECT_GT(j["draw_ms"].get<double>(), 0.0);
  EXPECT_GE(j["load_s"].get<double>(), 0.0);
  EXPECT_FALSE(j["renderer"].get<std::string>().empty());
  EXPECT_EQ(j["output"], out.string());
  Image image = load_image(out);
  ASSERT_EQ(image.width, 64);
  ASSERT_EQ(image.height, 48);
  // The sphere is in the middle, the corners are background (and differ from it).
  EXPECT_NE(std::vector(image.pixel(32, 24), image.pixel(32, 24) + 3),
            std::vector(image.pixel(0, 0), image.pixel(0, 0) + 3));
  EXPECT_EQ(std::vector(image.pixel(0, 0), image.pixel(0, 0) + 4),
            std::vector(image.pixel(63, 47), image.pixel(63, 47) + 4));
}

TEST(CliRender, SameInputSameBytes) {
  auto dir = test::temp_dir();
  for (const char* name : {"a.png", "b.png"}) {
    auto r = test::run_lodstream({"render", sphere_obj().string(), "--eye", "1,2,3", "--target", "0,0.2,0",
                                  "--fov", "45", "--size", "80x60", "-o", (dir / name).string()});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  EXPECT_EQ(slurp(dir / "a.png"), slurp(dir / "b.png"));
}

TEST(CliRender, CameraFileGivesTheSameImageAsOptions) {
  auto dir = test::temp_dir();
  std::ofstream(dir / "cam.json") << R"({"eye": [1, 2, 3], "target": [0, 0.2, 0], "up": [0, 1, 0], "fov": 45,
                                         "size": [80, 60]})";
  ASSERT_EQ(test::run_lodstream({"render", sphere_obj().string(), "--camera", (dir / "cam.json").string(),
                                 "-o", (dir / "file.png").string()})
                .status,
            0);
  ASSERT_EQ(test::run_lodstream({"render", sphere_obj().string(), "--eye", "1,2,3", "--target", "0,0.2,0",
                                 "--fov", "45", "--size", "80x60", "-o", (dir / "options.png").string()})
                .status,
            0);
  EXPECT_EQ(slurp(dir / "file.png"), slurp(dir / "options.png"));
  // --size overrides the file's size.
  auto r = test::run_lodstream({"render", sphere_obj().string(), "--camera", (dir / "cam.json").string(),
                                "--size", "40x30", "-o", (dir / "small.png").string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.json()["width"], 40);
  EXPECT_EQ(load_image(dir / "small.png").height, 30);
}

TEST(CliRender, RealModel) {
  auto out = test::temp_dir() / "bunny.png";
  auto r = test::run_lodstream({"render", test::data_file("bunny.obj").string(), "--eye", "0,0.15,0.3",
                                "--target", "0,0.1,0", "--size", "96x64", "-o", out.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_GT(r.json()["triangles"].get<int>(), 60000);
}

TEST(CliRender, BadInputIsAOneLineError) {
  auto dir = test::temp_dir();
  const std::string model = sphere_obj().string(), png = (dir / "x.png").string();
  const std::vector<std::string> cam = {"--eye", "0,0,4", "--target", "0,0,0"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"render", model};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  auto with_cam = [&](std::vector<std::string> extra) {
    auto args = with(cam);
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  expect_error({"render", (dir / "missing.obj").string(), "--eye", "0,0,4", "--target", "0,0,0", "-o", png},
               "missing.obj");
  std::ofstream(dir / "garbage.ply") << "this is not a ply file\n";
  expect_error({"render", (dir / "garbage.ply").string(), "--eye", "0,0,4", "--target", "0,0,0", "-o", png},
               "garbage.ply");
  expect_error(with({"-o", png}), "camera");
  expect_error(with_cam({"--size", "0x10", "-o", png}), "--size");
  expect_error(with_cam({"--size", "big", "-o", png}), "--size");
  expect_error(with({"--eye", "1,2", "--target", "0,0,0", "-o", png}), "--eye");
  expect_error(with({"--eye", "0,0,0", "--target", "0,0,0", "-o", png}), "same point");
  expect_error(with_cam({"--fov", "190", "-o", png}), "fov");
  expect_error(with_cam({"--frames", "0", "-o", png}), "--frames");
  expect_error(with_cam({"-o", (dir / "no-such-folder" / "x.png").string()}), "no-such-folder");
  expect_error(with_cam({"-o", (dir / "x.jpg").string()}), ".png");
  expect_error(with({"--camera", (dir / "none.json").string(), "-o", png}), "none.json");
  std::ofstream(dir / "bad.json") << "{\"eye\": [0, 0, 4], \"target\": ";
  expect_error(with({"--camera", (dir / "bad.json").string(), "-o", png}), "bad.json");
  std::ofstream(dir / "cam.json") << R"({"eye": [0, 0, 4], "target": [0, 0, 0]})";
  expect_error(with({"--camera", (dir / "cam.json").string(), "--eye", "1,1,1", "-o", png}), "--camera");
  EXPECT_FALSE(std::filesystem::exists(png));
}
