// `lodstream view --headless` end to end: a baked package read locally, pulled from `lodstream serve` and
// from a real nginx, and pushed to by `lodstream serve`, each reaching the converged cut (last CSV row:
// benefit ratio 1) for a fixed camera; 16 clients on one server; the window mode under Xvfb; bad input.
#include <gtest/gtest.h>

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <thread>

#include "baked.hpp"
#include "core/image.hpp"
#include "net/wire.hpp"
#include "render/renderer.hpp"
#include "support/nginx.hpp"
#include "support/run.hpp"
#include "support/xvfb.hpp"
#include "view_run.hpp"

using namespace lodstream;
using namespace lodstream::test;

TEST(View, ALocalFileConvergesForAFixedCamera) {
  const auto v = view(test::elephant_package().string(), camera_path({}, {0.0f, 0.2f, 1.5f}, 0));
  expect_converged(v, "file");
}

// --order full (bench stream's `full` policy): nothing is drawn until every page it fetches has arrived,
// then the finest cut (more triangles than the converged cut at tau). --window N (the sse-pull baselines'
// request window) converges as the byte window does.
TEST(View, OrderFullDrawsNothingUntilTheFinestLevelArrivedAndAWindowOfRequestsConverges) {
  const auto path = camera_path({}, {0.0f, 0.5f, 8.0f}, 0);  // far: the cut at tau is coarser than the finest
  Server server;
  const auto full = view(server.http(), path, {"--order", "full"});
  expect_converged(full, "pull");
  ASSERT_FALSE(full.rows.empty());
  const double total = full.rows.back().at(1);
  for (const auto& row : full.rows) {
    if (row.at(1) < total) {
      EXPECT_EQ(row.at(2), 0.0) << "t=" << row.at(0);  // nodes
    }
  }
  const auto windowed = view(server.http(), path, {"--order", "sse", "--window", "3"});
  expect_converged(windowed, "pull");
  // the finest level: more triangles than the converged cut at tau, and no error left
  EXPECT_GT(full.rows.back().at(3), windowed.rows.back().at(3));
  EXPECT_EQ(full.rows.back().at(4), 0.0);
}

TEST(View, PullsFromServeAndFromNginxAndIsPushedTo) {
  const auto path = camera_path({0.0f, 0.0f, 3.0f}, {0.8f, 0.2f, 0.8f}, 1.0);
  Server server;
  expect_converged(view(server.http(), path), "pull");
  expect_converged(view(server.ws(), path), "push");
  const auto root = test::temp_dir();
  std::filesystem::copy_file(test::elephant_package(), root / "elephant.lods");
  test::Nginx nginx(root);
  expect_converged(view("http://127.0.0.1:" + std::to_string(nginx.port()) + "/elephant.lods", path), "pull");
}

TEST(View, TheFinalFrameOfAPushedViewIsTheRenderOfTheCut) {
  // Issue 5's correctness: once converged, the client draws what `lodstream render --pixel-error 1` draws.
  const auto path = camera_path({0.0f, 0.0f, 3.0f}, {0.8f, 0.2f, 0.8f}, 0.5);
  Server server;
  const auto v = view(server.ws(), path, {"--frames-every", "1000"});
  expect_converged(v, "push");
  expect_final_frame_is_render(v, elephant_package(), {0.8f, 0.2f, 0.8f});
}

TEST(View, SixteenClientsOnOneServerConvergeWhileAGarbageClientGetsBye) {
  Server server;
  std::vector<ViewRun> runs(16);
  std::vector<std::thread> clients;
  for (int i = 0; i < 16; ++i) {
    const float a = 0.4f * float(i);
    const auto path = camera_path({3.0f * std::sin(a), 0.5f, 3.0f * std::cos(a)},
                                  {1.2f * std::sin(a), 0.2f, 1.2f * std::cos(a)}, 1.0);
    clients.emplace_back([&, i, path] { runs[i] = view(i % 2 ? server.ws() : server.http(), path); });
  }
  {
    // A WebSocket client that sends garbage: the server ends that session with a Bye.
    namespace asio = boost::asio;
    namespace beast = boost::beast;
    asio::io_context io;
    beast::websocket::stream<asio::ip::tcp::socket> ws(io);
    ws.next_layer().connect({asio::ip::make_address("127.0.0.1"), server.port});
    ws.binary(true);
    ws.handshake("127.0.0.1", "/elephant");
    const std::vector<uint8_t> garbage{1, 2, 3, 4, 5, 6, 7, 8, 9};
    ws.write(asio::buffer(garbage));
    beast::flat_buffer buffer;
    ws.read(buffer);
    const auto* data = static_cast<const uint8_t*>(buffer.data().data());
    const wire::Message m = wire::decode(std::span<const uint8_t>(data, buffer.size()));
    ASSERT_TRUE(std::holds_alternative<wire::Bye>(m)) << wire::type_name(m);
  }
  for (auto& c : clients) c.join();
  for (int i = 0; i < 16; ++i) {
    SCOPED_TRACE("client " + std::to_string(i));
    expect_converged(runs[i], i % 2 ? "push" : "pull");
  }
  EXPECT_EQ(server.process.stop(), 0);
}

namespace {

// Pixels of `image` other than the background: in all, and in its middle half (both axes).
std::pair<size_t, size_t> covered_pixels(const Image& image) {
  size_t covered = 0, middle = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const uint8_t* p = image.pixel(x, y);
      if (std::equal(p, p + 3, render::kBackground.begin())) continue;
      ++covered;
      if (std::abs(x - image.width / 2) < image.width / 4 &&
          std::abs(y - image.height / 2) < image.height / 4)
        ++middle;
    }
  return {covered, middle};
}

}  // namespace

TEST(View, AWindowUnderXvfbDrawsWhatItStreamedAndExitsAfterItsFrames) {
  test::Xvfb x(800, 600);
  ASSERT_FALSE(x.display().empty()) << "Xvfb did not start (scripts/setup installs xvfb)";
  Server server;
  // `frames` frames in a window; the last one as `shot`; returns the JSON summary.
  auto window = [&](std::vector<std::string> args, const std::filesystem::path& shot) {
    args.insert(args.end(), {"--frames", "45", "--screenshot", shot.string(), "--json"});
    setenv("DISPLAY", x.display().c_str(), 1);
    const auto r = test::run_lodstream(args);
    unsetenv("DISPLAY");
    EXPECT_EQ(r.status, 0) << r.err;
    return r.status == 0 ? r.json() : nlohmann::json::object();
  };
  // The run's summary (45 frames of `mode`, bytes and triangles) and its screenshot: width x height, at least
  // 1/min_share of it covered, mostly in the middle.
  auto expect_drawn = [](const nlohmann::json& j, const char* mode, const std::filesystem::path& shot,
                         int width, int height, size_t min_share) {
    EXPECT_EQ(j["mode"], mode);
    EXPECT_EQ(j["frames"], 45);
    EXPECT_GT(j["bytes"].get<uint64_t>(), 0u);
    EXPECT_GT(j["triangles"].get<uint64_t>(), 0u);
    const Image image = load_image(shot);
    ASSERT_EQ(image.width, width);
    ASSERT_EQ(image.height, height);
    const auto [covered, middle] = covered_pixels(image);
    EXPECT_GT(covered, size_t(width * height) / min_share) << "the frame is (nearly) empty";
    EXPECT_GT(middle, covered / 2);
  };
  {
    // Pulled, starting at the path's first key frame: the elephant in the middle of a 640x480 window.
    SCOPED_TRACE("pull, --path");
    const auto shot = test::temp_dir() / "window_pull.png";
    const auto path = camera_path({}, {0.0f, 0.2f, 1.5f}, 0);
    expect_drawn(window({"view", server.http(), "--path", path.string()}, shot), "pull", shot, 640, 480, 50);
  }
  {
    // Pushed, with no path: the start pose is fitted to the scene's bounds (3 radii out, at its centre).
    SCOPED_TRACE("push, fitted start");
    const auto shot = test::temp_dir() / "window_push.png";
    expect_drawn(window({"view", server.ws(), "--size", "320x240"}, shot), "push", shot, 320, 240, 200);
  }
  EXPECT_EQ(server.process.stop(), 0);
}

TEST(View, BadInputIsAOneLineError) {
  const auto path = camera_path({}, {0.0f, 0.0f, 2.0f}, 0);
  const auto out = (test::temp_dir() / "bad").string();
  auto expect_error = [](const test::RunResult& r, const std::string& needle) {
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err.rfind("lodstream: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  };
  expect_error(
      test::run_lodstream({"view", "/nonexistent.lods", "--headless", "--path", path.string(), "--out", out}),
      "nonexistent.lods");
  expect_error(
      test::run_lodstream({"view", test::elephant_package().string(), "--path", path.string(), "--out", out}),
      "--headless");
  expect_error(test::run_lodstream({"view", test::elephant_package().string(), "--headless", "--out", out}),
               "--path");
  expect_error(test::run_lodstream({"view", "ws://127.0.0.1:1/elephant", "--headless", "--path",
                                    path.string(), "--out", out}),
               "127.0.0.1");
  expect_error(test::run_lodstream({"view", test::elephant_package().string(), "--headless", "--path",
                                    path.string(), "--out", out, "--pixel-error", "0"}),
               "--pixel-error");
  expect_error(test::run_lodstream({"view", test::elephant_package().string(), "--headless", "--path",
                                    path.string(), "--out", out, "--order", "warp"}),
               "--order");
  expect_error(test::run_lodstream({"view", test::elephant_package().string(), "--headless", "--path",
                                    path.string(), "--out", out, "--window", "65"}),
               "--window");
  expect_error(test::run_lodstream({"view", "ws://127.0.0.1:1/elephant", "--headless", "--path",
                                    path.string(), "--out", out, "--order", "full"}),
               "--order");
  // A window without an X display: GLFW's reason, in one line.
  const char* display = std::getenv("DISPLAY");
  const std::string saved = display ? display : "";
  unsetenv("DISPLAY");
  expect_error(test::run_lodstream({"view", test::elephant_package().string(), "--frames", "1"}), "DISPLAY");
  if (display) setenv("DISPLAY", saved.c_str(), 1);
}
