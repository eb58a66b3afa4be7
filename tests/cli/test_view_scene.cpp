// Issue 5's correctness on a multi-object scene: the baked motorBike (67 objects), pushed to by `lodstream
// serve`, pulled from it and pulled from a real nginx, converges to the cut `lodstream render --pixel-error
// 1` draws for the final view, and its final frame is that render (identical pixels or PSNR >= 50 dB).
#include <gtest/gtest.h>

#include "support/nginx.hpp"
#include "view_run.hpp"

using namespace lodstream;
using namespace lodstream::test;

TEST(ViewScene, MotorBikeConvergesToTheRenderOfItsCutPushedPulledAndThroughNginx) {
  const std::filesystem::path& package = motorbike_package();
  // examples/cameras/motorBike_side.json's view (z up), approached from further out over half a second.
  const glm::vec3 eye{0.73f, -2.9f, 0.75f}, target{0.73f, 0.0f, 0.65f}, up{0.0f, 0.0f, 1.0f};
  const auto path = camera_path({1.5f, -4.5f, 1.2f}, eye, 0.5, target, up);
  Server server(package);
  const auto root = temp_dir();
  std::filesystem::copy_file(package, root / "motorBike.lods");
  Nginx nginx(root);
  const std::vector<std::pair<std::string, std::string>> sources{
      {server.ws(), "push"},
      {server.http(), "pull"},
      {"http://127.0.0.1:" + std::to_string(nginx.port()) + "/motorBike.lods", "pull"}};
  for (const auto& [source, mode] : sources) {
    SCOPED_TRACE(source);
    const ViewRun v = view(source, path, {"--frames-every", "1000"});
    expect_converged(v, mode);
    expect_final_frame_is_render(v, package, eye, target, up);
  }
}
