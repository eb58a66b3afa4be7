// A client cache that outlives the process (`view --cache-dir`), end to end: a second run of the same view
// starts from the pages the first one stored, tells a push server what it holds (the Hello's held pages, by
// content hash) or does not request them (pull), so that no page is ever sent twice; a corrupt cached page is
// dropped with a warning and fetched again; a server restarted mid-path is reconnected to, and no page
// arrives twice over both sessions.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <map>
#include <optional>
#include <thread>

#include "net/link_proxy.hpp"
#include "view_run.hpp"

using namespace lodstream;
using namespace lodstream::test;

namespace {

// Bytes of the page files under a --cache-dir: what the client stored, each page once (a file being written,
// *.tmp, is not counted).
uint64_t stored_bytes(const std::filesystem::path& dir) {
  uint64_t n = 0;
  std::error_code ec;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir, ec))
    if (e.is_regular_file() && !e.path().string().ends_with(".tmp")) n += e.file_size();
  return n;
}

uint64_t bytes(const ViewRun& v, const char* key) {
  return v.result.json()[key].get<uint64_t>();
}

// A camera path that swings from one side of the elephant to the other and back in 4 s.
std::filesystem::path swing_path() {
  const auto path = temp_dir() / "swing.json";
  nlohmann::json keys = nlohmann::json::array();
  for (const auto& [t, x] : {std::pair(0.0, 0.8), std::pair(2.0, -0.8), std::pair(4.0, 0.8)})
    keys.push_back({{"t", t}, {"eye", {x, 0.2, x}}, {"target", {0, 0, 0}}, {"up", {0, 1, 0}}});
  std::ofstream(path) << nlohmann::json{{"fov", 60}, {"size", {640, 480}}, {"keyframes", keys}}.dump();
  return path;
}

// `lodstream view SOURCE` along `path` as a thin client: a 0.3 MB memory cache, pages kept under `dir`.
RunResult thin_view(const std::string& source, const std::filesystem::path& path,
                    const std::filesystem::path& dir) {
  return run_lodstream({"view", source, "--headless", "--path", path.string(), "--out",
                        (temp_dir() / "out").string(), "--settle", "2", "--cache", "0.3", "--cache-dir",
                        dir.string(), "--json"});
}

}  // namespace

TEST(ViewReconnect, APushedViewStartedAgainFromItsCacheIsSentNothingTwice) {
  Server server;
  const auto path = camera_path({}, {0.8f, 0.2f, 0.8f}, 0);
  const std::string dir = (temp_dir() / "cache").string();
  const ViewRun first = view(server.ws(), path, {"--cache-dir", dir});
  expect_converged(first, "push");
  EXPECT_EQ(bytes(first, "bytes_restored"), 0u);
  const uint64_t after_first = stored_bytes(dir);
  EXPECT_EQ(after_first, bytes(first, "bytes"));  // every page that arrived was stored, once

  const ViewRun second = view(server.ws(), path, {"--cache-dir", dir});
  expect_converged(second, "push");
  EXPECT_EQ(bytes(second, "bytes_restored"), after_first);
  // The server sent only pages the Hello did not list: the stored bytes grew by exactly what arrived.
  EXPECT_EQ(stored_bytes(dir), after_first + bytes(second, "bytes"));
  // Everything the view needs was on disk: the first frame is the converged one.
  EXPECT_EQ(second.rows.size(), 1u);
  EXPECT_EQ(second.rows.front().at(6), 1.0);
}

TEST(ViewReconnect, APulledViewStartedAgainRequestsNothingItHoldsAndRefetchesACorruptPage) {
  Server server;
  const auto path = camera_path({}, {0.0f, 0.3f, 1.2f}, 0);
  const auto dir = temp_dir() / "cache";
  const ViewRun first = view(server.http(), path, {"--cache-dir", dir.string()});
  expect_converged(first, "pull");
  const uint64_t after_first = stored_bytes(dir);
  EXPECT_EQ(after_first, bytes(first, "bytes"));

  const ViewRun second = view(server.http(), path, {"--cache-dir", dir.string()});
  expect_converged(second, "pull");
  EXPECT_EQ(bytes(second, "bytes"), 0u);  // nothing requested: the cut was whole from the first frame
  EXPECT_EQ(bytes(second, "bytes_restored"), after_first);
  EXPECT_EQ(second.rows.size(), 1u);

  // One cached data page flipped on disk: dropped with a warning naming it, fetched again, never drawn.
  std::filesystem::path page;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename().string()[0] == 'd') page = e.path();
  ASSERT_FALSE(page.empty());
  const uint64_t page_bytes = std::filesystem::file_size(page);
  {
    std::fstream f(page, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(long(page_bytes / 2));
    const char c = char(f.get());
    f.seekp(long(page_bytes / 2));
    f.put(char(c ^ 0x5a));
  }
  const ViewRun third = view(server.http(), path, {"--cache-dir", dir.string()});
  expect_converged(third, "pull");
  EXPECT_NE(third.result.err.find("lodstream: warning: " + page.string()), std::string::npos)
      << third.result.err;
  EXPECT_NE(third.result.err.find("checksum"), std::string::npos) << third.result.err;
  EXPECT_EQ(bytes(third, "bytes_restored"), after_first - page_bytes);
  EXPECT_LE(bytes(third, "bytes"), page_bytes);  // at most that page again (if this view draws it)
  EXPECT_EQ(stored_bytes(dir), after_first - page_bytes + bytes(third, "bytes"));
}

TEST(ViewReconnect, AServerRestartedMidPathIsReconnectedToAndNoPageArrivesTwice) {
  // The client reaches the server through a 2 Mbit/s link, so that the server is stopped with pages still to
  // send (once the first page is stored); it starts again on the same port 1.5 s later while the client draws
  // what it holds. The camera comes closer meanwhile, so the client asks for pages while the server is down
  // (a far view's first page can be all it needs until then: a shorter outage could pass unnoticed).
  const auto path = camera_path({0.0f, 0.0f, 3.0f}, {0.8f, 0.2f, 0.8f}, 2.0);
  for (const std::string mode : {"push", "pull"}) {
    SCOPED_TRACE(mode);
    std::optional<Server> server(std::in_place);
    const uint16_t port = server->port;
    LinkSettings slow;
    slow.bandwidth_bps = 2e6;
    slow.rtt_s = 0.02;
    LinkProxy link("127.0.0.1", 0, "127.0.0.1", port, slow);
    const std::string at = "127.0.0.1:" + std::to_string(link.port());
    const std::string source =
        mode == "push" ? "ws://" + at + "/elephant" : "http://" + at + "/elephant.lods";
    const auto dir = temp_dir() / "cache";
    ViewRun run;
    std::thread client([&] { run = view(source, path, {"--cache-dir", dir.string()}); });
    // Stopped as soon as the first page is stored (within 20 s).
    for (int i = 0; i < 1000 && stored_bytes(dir) == 0; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const uint64_t before = stored_bytes(dir);
    EXPECT_EQ(server->process.stop(), 0);
    server.reset();
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    server.emplace(elephant_package(), port);
    client.join();
    expect_converged(run, mode);
    const auto j = run.result.json();
    EXPECT_GT(before, 0u);                          // the first server sent pages …
    EXPECT_GT(j["bytes"].get<uint64_t>(), before);  // … and the second the rest
    EXPECT_GE(j["reconnects"].get<uint64_t>(), 1u);
    EXPECT_EQ(stored_bytes(dir), j["bytes"].get<uint64_t>());  // every page arrived once over both sessions
  }
}

TEST(ViewReconnect, APulledThinClientReadsEvictedPagesBackFromDiskNotFromTheNetwork) {
  // A 0.3 MB memory cache on the 0.88 MB elephant and a camera that swings to the far side and back: pages
  // are evicted and needed again. With --cache-dir every page crosses the network once; the pages needed
  // again are read back from disk.
  Server server;
  const auto path = swing_path();
  const auto dir = temp_dir() / "cache";
  const auto r = thin_view(server.http(), path, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = r.json();
  EXPECT_GT(j["bytes"].get<uint64_t>(), 0u);
  EXPECT_EQ(j["bytes"].get<uint64_t>(), stored_bytes(dir));  // no page came over the network twice
  EXPECT_GT(j["bytes_restored"].get<uint64_t>(), 0u);        // evicted pages were read back from disk
  EXPECT_GT(j["benefit_ratio"].get<double>(), 0.0);
}

TEST(ViewReconnect, APushedThinClientIsToldToRestoreEvictedPagesFromDiskNotSentThemAgain) {
  // As above, pushed: the client says which evicted pages its disk keeps, and the server sends a Restore
  // instead of their bytes. A second run of the path starts from the disk, its Hello listing the pages the
  // memory budget left there: still no page crosses the network twice over both runs. A third, after the
  // upper half of the data page files was corrupted (pages restored at start-up go in page order until the
  // budget is spent, so those stay on disk, listed in the Hello): Restores fail their checksum, and the
  // server sends the bytes instead.
  Server server;
  const auto path = swing_path();
  const auto dir = temp_dir() / "cache";
  auto run = [&](bool corrupt) {
    const auto r = thin_view(server.ws(), path, dir);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err.find("restore asked of the disk cache failed") != std::string::npos, corrupt) << r.err;
    return r.json();
  };
  const auto first = run(false);
  EXPECT_GT(first["bytes"].get<uint64_t>(), 0u);
  EXPECT_EQ(first["bytes"].get<uint64_t>(), stored_bytes(dir));  // no page came over the network twice
  EXPECT_GT(first["bytes_restored"].get<uint64_t>(), 0u);        // evicted pages were restored from disk
  EXPECT_GT(first["benefit_ratio"].get<double>(), 0.0);
  const auto second = run(false);
  EXPECT_GT(second["bytes_restored"].get<uint64_t>(), 0u);
  EXPECT_EQ(stored_bytes(dir), first["bytes"].get<uint64_t>() + second["bytes"].get<uint64_t>());
  EXPECT_GT(second["benefit_ratio"].get<double>(), 0.0);

  std::map<int, std::filesystem::path> data_pages;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename().string().starts_with("d"))
      data_pages[std::stoi(e.path().filename().string().substr(1))] = e.path();
  ASSERT_GE(data_pages.size(), 4u);
  size_t i = 0;
  for (const auto& [id, file] : data_pages)
    if (i++ >= data_pages.size() / 2) {
      std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
      f.seekg(std::streamoff(std::filesystem::file_size(file) / 2));
      const char c = char(f.get());
      f.seekp(std::streamoff(std::filesystem::file_size(file) / 2));
      f.put(char(c ^ 0x5a));  // same size, wrong checksum
    }
  const auto third = run(true);
  EXPECT_GT(third["bytes"].get<uint64_t>(), 0u);  // what could not be restored came as bytes
  EXPECT_GT(third["benefit_ratio"].get<double>(), 0.0);
}

TEST(ViewReconnect, ACacheDirThatCannotBeCreatedIsAOneLineError) {
  const auto file = temp_dir() / "a_file";
  std::ofstream(file) << "not a directory";
  const auto path = camera_path({}, {0.0f, 0.0f, 2.0f}, 0);
  const auto r = run_lodstream({"view", elephant_package().string(), "--headless", "--path", path.string(),
                                "--out", (temp_dir() / "out").string(), "--cache-dir", file.string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err.rfind("lodstream: error: " + file.string() + "/", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("cannot create the cache directory"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}
