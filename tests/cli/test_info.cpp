// `lodstream info` end to end on the real test data, and its bad-input behaviour.
#include <gtest/gtest.h>

#include <fstream>

#include "support/run.hpp"

using namespace lodstream::test;

namespace {

nlohmann::json info(const std::string& name) {
  auto r = run_lodstream({"info", data_file(name).string(), "--json"});
  EXPECT_EQ(r.status, 0) << r.err;
  return r.json();
}

}  // namespace

TEST(Info, RealMeshesHaveTheirKnownTriangleCounts) {
  // Counts as the files hold them (faces of the OFF / PLY / OBJ); the OFF files have no normals, so they get
  // computed ones.
  struct Case {
    const char* file;
    size_t triangles, objects;
  };
  for (auto c :
       {Case{"elephant.off", 5558, 1}, Case{"refined_elephant.off", 88928, 1}, Case{"horse.ply", 96966, 1},
        Case{"bunny.obj", 69666, 1}, Case{"motorBike.obj", 331653, 67}}) {
    auto j = info(c.file);
    EXPECT_EQ(j["triangles"], c.triangles) << c.file;
    EXPECT_EQ(j["unique_triangles"], c.triangles) << c.file;
    EXPECT_EQ(j["objects"], c.objects) << c.file;
    EXPECT_TRUE(j["attributes"]["normals"].get<bool>()) << c.file;
    EXPECT_GT(j["vertices"].get<size_t>(), c.triangles / 3) << c.file;
    EXPECT_LT(j["vertices"].get<size_t>(), c.triangles) << c.file;  // welded: about half as many as triangles
    for (int k = 0; k < 3; ++k)
      EXPECT_LT(j["bounds"]["min"][k].get<float>(), j["bounds"]["max"][k].get<float>());
    EXPECT_GE(j["time_s"].get<double>(), 0.0);
  }
}

TEST(Info, HorseHasColorsAndBuildingsDropsDegenerateFaces) {
  EXPECT_TRUE(info("horse.ply")["attributes"]["colors"].get<bool>());
  auto r = run_lodstream({"info", data_file("buildings.obj").string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  // 400,020 faces in the file, of which 284 have zero area (reported in one warning line).
  EXPECT_EQ(r.json()["triangles"], 400020 - 284);
  EXPECT_NE(r.err.find("dropped 284 degenerate"), std::string::npos) << r.err;
}

TEST(Info, TexturedGltfThroughTheWorker) {
  auto j = info("dungeon/level-dungeon.gltf");
  EXPECT_EQ(j["objects"], 57);
  EXPECT_TRUE(j["attributes"]["uvs"].get<bool>());
  size_t textured = 0;
  for (const auto& m : j["materials"]) {
    ASSERT_TRUE(m.contains("name") && m.contains("base_color") && m.contains("texture"));
    if (m["texture"].is_string()) {
      std::string path = m["texture"];
      EXPECT_EQ(path.front(), '/');
      EXPECT_TRUE(std::ifstream(path).good()) << path;
      ++textured;
    }
  }
  EXPECT_GE(textured, 5u);
}

TEST(Info, HumanOutput) {
  auto r = run_lodstream({"info", data_file("elephant.off").string()});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("5558"), std::string::npos) << r.out;
}

TEST(Info, BadInputExitsWithOneLineError) {
  auto dir = temp_dir();
  std::ofstream(dir / "bad.ply")
      << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n";
  std::ofstream(dir / "bad.stl") << "this is not an STL file at all";
  for (auto file : {dir / "bad.ply", dir / "bad.stl", dir / "missing.obj"}) {
    auto r = run_lodstream({"info", file.string(), "--json"});
    EXPECT_EQ(r.status, 1) << file;
    EXPECT_EQ(r.err.rfind("lodstream: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(file.string()), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}
