// `lodstream view --headless` end to end: a baked package read locally, pulled from `lodstream serve` and
// from a real nginx, and pushed to by `lodstream serve`, each reaching the converged cut (last CSV row:
// benefit ratio 1) for a fixed camera; 16 clients on one server; bad input.
#include <gtest/gtest.h>

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <fstream>
#include <sstream>
#include <thread>

#include "baked.hpp"
#include "net/wire.hpp"
#include "support/nginx.hpp"
#include "support/run.hpp"

using namespace lodstream;

namespace {

// A camera path: from `from` to `to` (looking at the origin) over `seconds` (0: a fixed camera at `to`).
std::filesystem::path camera_path(glm::vec3 from, glm::vec3 to, double seconds) {
  static int count = 0;
  auto file = test::temp_dir() / ("path" + std::to_string(count++) + ".json");
  auto key = [](double t, glm::vec3 e) {
    return nlohmann::json{{"t", t}, {"eye", {e.x, e.y, e.z}}, {"target", {0, 0, 0}}};
  };
  nlohmann::json j{{"fov", 60}, {"size", {640, 480}}, {"keyframes", nlohmann::json::array()}};
  if (seconds > 0) j["keyframes"].push_back(key(0.0, from));
  j["keyframes"].push_back(key(seconds, to));
  std::ofstream(file) << j.dump();
  return file;
}

struct ViewRun {
  std::filesystem::path out;
  test::RunResult result;
  std::vector<std::vector<double>> rows;
  std::string header;
};

ViewRun view(const std::string& source, const std::filesystem::path& path,
             std::vector<std::string> more = {}) {
  static int count = 0;
  const auto out = test::temp_dir() / ("view" + std::to_string(count++));
  ViewRun v;
  std::vector<std::string> args{"view",  source,       "--headless", "--path", path.string(),
                                "--out", out.string(), "--settle",   "20",     "--json"};
  args.insert(args.end(), more.begin(), more.end());
  v.result = test::run_lodstream(args);
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
void expect_converged(const ViewRun& v, const std::string& mode) {
  ASSERT_EQ(v.result.status, 0) << v.result.err;
  EXPECT_EQ(v.header, "t,bytes,nodes,triangles,pixel_error_max,pixel_error_mean,benefit_ratio,frame_ms");
  ASSERT_FALSE(v.rows.empty());
  EXPECT_EQ(v.rows.back().at(6), 1.0);
  EXPECT_LE(v.rows.back().at(4), 1.0);  // pixel error max within tau
  EXPECT_GT(v.rows.back().at(1), 0.0);  // bytes arrived
  const auto j = v.result.json();
  EXPECT_EQ(j["mode"], mode);
  EXPECT_EQ(j["converged"], true);
  EXPECT_EQ(j["benefit_ratio"], 1.0);
  // Bytes and triangles never decrease over the frames (nothing was evicted: the cache is large).
  for (size_t i = 1; i < v.rows.size(); ++i) EXPECT_GE(v.rows[i][1], v.rows[i - 1][1]);
}

struct Server {
  test::BackgroundProcess process{{"serve", test::elephant_package().string(), "--port", "0"}};
  uint16_t port = 0;
  Server() {
    std::string line = process.read_line();
    EXPECT_EQ(line.rfind("listening on http://127.0.0.1:", 0), 0u) << line;
    port = uint16_t(std::stoi(line.substr(line.rfind(':') + 1)));
  }
  std::string http() const { return "http://127.0.0.1:" + std::to_string(port) + "/elephant.lods"; }
  std::string ws() const { return "ws://127.0.0.1:" + std::to_string(port) + "/elephant"; }
};

}  // namespace

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
  const auto frames = v.rows.size() - 1;
  char name[64];
  std::snprintf(name, sizeof name, "frame_%05zu.png", frames);
  ASSERT_TRUE(std::filesystem::exists(v.out / name)) << name;
  const auto reference = test::temp_dir() / "reference.png";
  auto r = test::run_lodstream({"render", test::elephant_package().string(), "--eye", "0.8,0.2,0.8",
                                "--target", "0,0,0", "--fov", "60", "--size", "640x480", "--pixel-error", "1",
                                "-o", reference.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  auto m =
      test::run_lodstream({"measure", "--images", (v.out / name).string(), reference.string(), "--json"});
  ASSERT_EQ(m.status, 0) << m.err;
  const auto j = m.json();
  EXPECT_TRUE(j["psnr"].is_null() || j["psnr"].get<double>() >= 50.0) << j.dump();
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
}
