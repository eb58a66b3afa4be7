// Helpers for the end-to-end tests of `lodstream view --headless`: camera paths, a run of the client with its
// CSV read back, the convergence checks, the final frame compared with `lodstream render` of the same cut,
// and a `lodstream serve` of one package. Header-only (the including test links Boost for the server).
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <glm/glm.hpp>
#include <sstream>

#include "baked.hpp"
#include "support/run.hpp"

namespace lodstream::test {

// A camera path looking at `target` (up `up`): from `from` to `to` over `seconds` (0: a fixed camera at
// `to`), 60° vertical field of view, 640x480.
inline std::filesystem::path camera_path(glm::vec3 from, glm::vec3 to, double seconds, glm::vec3 target = {},
                                         glm::vec3 up = {0.0f, 1.0f, 0.0f}) {
  static int count = 0;
  auto file = temp_dir() / ("path" + std::to_string(count++) + ".json");
  auto key = [&](double t, glm::vec3 e) {
    return nlohmann::json{{"t", t},
                          {"eye", {e.x, e.y, e.z}},
                          {"target", {target.x, target.y, target.z}},
                          {"up", {up.x, up.y, up.z}}};
  };
  nlohmann::json j{{"fov", 60}, {"size", {640, 480}}, {"keyframes", nlohmann::json::array()}};
  if (seconds > 0) j["keyframes"].push_back(key(0.0, from));
  j["keyframes"].push_back(key(seconds, to));
  std::ofstream(file) << j.dump();
  return file;
}

struct ViewRun {
  std::filesystem::path out;
  RunResult result;
  std::vector<std::vector<double>> rows;
  std::string header;
};

// `lodstream view SOURCE --headless --path PATH --out (fresh dir) --settle 20 --json MORE…`, its CSV read.
inline ViewRun view(const std::string& source, const std::filesystem::path& path,
                    std::vector<std::string> more = {}) {
  static int count = 0;
  const auto out = temp_dir() / ("view" + std::to_string(count++));
  ViewRun v;
  std::vector<std::string> args{"view",  source,       "--headless", "--path", path.string(),
                                "--out", out.string(), "--settle",   "20",     "--json"};
  args.insert(args.end(), more.begin(), more.end());
  v.result = run_lodstream(args);
  v.out = out;
  std::ifstream csv(out / "frames.csv");
  std::getline(csv, v.header);
  for (std::string line; std::getline(csv, line);) {
    std::vector<double> row;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) row.push_back(std::stod(cell));
    v.rows.push_back(row);
  }
  return v;
}

// The run converged: exit 0, DESIGN's header, last row benefit ratio 1 and the JSON saying so.
inline void expect_converged(const ViewRun& v, const std::string& mode) {
  ASSERT_EQ(v.result.status, 0) << v.result.err;
  EXPECT_EQ(v.header, "t,bytes,nodes,triangles,pixel_error_max,pixel_error_mean,benefit_ratio,frame_ms");
  ASSERT_FALSE(v.rows.empty());
  EXPECT_EQ(v.rows.back().at(6), 1.0);
  EXPECT_LE(v.rows.back().at(4), 1.0);  // pixel error max within tau
  const auto j = v.result.json();
  // Pages arrived, or were kept from an earlier run (--cache-dir).
  EXPECT_GT(j["bytes"].get<uint64_t>() + j["bytes_restored"].get<uint64_t>(), 0u);
  EXPECT_EQ(j["mode"], mode);
  EXPECT_EQ(j["converged"], true);
  EXPECT_EQ(j["benefit_ratio"], 1.0);
  // Bytes and triangles never decrease over the frames (nothing was evicted: the cache is large).
  for (size_t i = 1; i < v.rows.size(); ++i) EXPECT_GE(v.rows[i][1], v.rows[i - 1][1]);
}

// Issue 5's correctness: the final frame of `v` (run with --frames-every) equals `lodstream render PACKAGE
// --pixel-error 1` from the path's last pose (`eye`, looking at `target`, `up`; 60°, 640x480): identical
// pixels or PSNR >= 50 dB.
inline void expect_final_frame_is_render(const ViewRun& v, const std::filesystem::path& package,
                                         glm::vec3 eye, glm::vec3 target = {},
                                         glm::vec3 up = {0.0f, 1.0f, 0.0f}) {
  ASSERT_FALSE(v.rows.empty());
  char name[64];
  std::snprintf(name, sizeof name, "frame_%05zu.png", v.rows.size() - 1);
  ASSERT_TRUE(std::filesystem::exists(v.out / name)) << name;
  auto vec = [](glm::vec3 p) {
    return std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.z);
  };
  const auto reference = v.out / "reference.png";
  auto r =
      run_lodstream({"render", package.string(), "--eye", vec(eye), "--target", vec(target), "--up", vec(up),
                     "--fov", "60", "--size", "640x480", "--pixel-error", "1", "-o", reference.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  auto m = run_lodstream({"measure", "--images", (v.out / name).string(), reference.string(), "--json"});
  ASSERT_EQ(m.status, 0) << m.err;
  const auto j = m.json();
  EXPECT_TRUE(j["psnr"].is_null() || j["psnr"].get<double>() >= 50.0) << j.dump();
}

// `lodstream serve PACKAGE --port P` (P = 0: a free one), its address read from the first line it prints.
struct Server {
  std::string name;
  BackgroundProcess process;
  uint16_t port = 0;
  explicit Server(const std::filesystem::path& package = elephant_package(), uint16_t at = 0)
      : name(package.stem().string()), process({"serve", package.string(), "--port", std::to_string(at)}) {
    std::string line = process.read_line();
    EXPECT_EQ(line.rfind("listening on http://127.0.0.1:", 0), 0u) << line;
    port = uint16_t(std::stoi(line.substr(line.rfind(':') + 1)));
  }
  std::string http() const { return "http://127.0.0.1:" + std::to_string(port) + "/" + name + ".lods"; }
  std::string ws() const { return "ws://127.0.0.1:" + std::to_string(port) + "/" + name; }
};

}  // namespace lodstream::test
