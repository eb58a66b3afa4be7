// Every file of DESIGN.md's test ladder goes through `info`, `render` and `measure` (issue 2's "done when").
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <map>

#include "core/image.hpp"
#include "support/run.hpp"

using namespace lodstream;

namespace {
const char* kLadder[] = {"elephant.off",  "bunny.obj",     "refined_elephant.off",      "horse.ply",
                         "motorBike.obj", "buildings.obj", "dungeon/level-dungeon.gltf"};

std::string csv(const glm::vec3& v) {
  return std::to_string(v.x) + "," + std::to_string(v.y) + "," + std::to_string(v.z);
}
}  // namespace

TEST(Ladder, InfoRenderAndMeasureWorkOnEveryFile) {
  auto dir = test::temp_dir();
  for (const char* name : kLadder) {
    SCOPED_TRACE(name);
    auto file = test::data_file(name).string();
    auto info = test::run_lodstream({"info", file, "--json"});
    ASSERT_EQ(info.status, 0) << info.err;
    auto j = info.json();
    EXPECT_GT(j["triangles"].get<size_t>(), 1000u);
    glm::vec3 lo{j["bounds"]["min"][0], j["bounds"]["min"][1], j["bounds"]["min"][2]};
    glm::vec3 hi{j["bounds"]["max"][0], j["bounds"]["max"][1], j["bounds"]["max"][2]};
    // An explicit camera outside the bounds, looking at their centre from a diagonal direction.
    glm::vec3 center = (lo + hi) * 0.5f, eye = center + glm::length(hi - lo) * glm::vec3(0.7f, 0.5f, 0.9f);
    auto png = (dir / "ladder.png").string();
    auto render = test::run_lodstream({"render", file, "--eye", csv(eye), "--target", csv(center), "--size",
                                       "256x144", "-o", png, "--json"});
    ASSERT_EQ(render.status, 0) << render.err;
    Image image = load_image(png);
    std::map<uint32_t, size_t> colours;
    for (size_t i = 0; i < image.rgba.size(); i += 4)
      ++colours[uint32_t(image.rgba[i]) << 16 | uint32_t(image.rgba[i + 1]) << 8 | image.rgba[i + 2]];
    size_t most = 0;
    for (auto& [c, n] : colours) most = std::max(most, n);
    EXPECT_LT(most, size_t(image.width) * size_t(image.height) * 99 / 100) << "the model is not in the image";
    auto self = test::run_lodstream({"measure", file, file, "--json"});
    ASSERT_EQ(self.status, 0) << self.err;
    EXPECT_LT(self.json()["hausdorff_relative"].get<double>(), 1e-5);
  }
}

TEST(Ladder, MeasureSeesTwoTessellationsOfTheSameShape) {
  auto r = test::run_lodstream({"measure", test::data_file("elephant.off").string(),
                                test::data_file("refined_elephant.off").string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  double h = r.json()["hausdorff_relative"].get<double>();
  EXPECT_GT(h, 1e-3);
  EXPECT_LT(h, 2e-2);
}
