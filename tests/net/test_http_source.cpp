#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <boost/asio.hpp>
#include <chrono>
#include <fstream>
#include <thread>

#include "core/error.hpp"
#include "net/http_server.hpp"
#include "net/http_source.hpp"
#include "package/reader.hpp"
#include "package/writer.hpp"
#include "raw_package.hpp"
#include "support/nginx.hpp"
#include "support/run.hpp"

using namespace lodstream;

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(HttpSource, PackageReaderOverHttpReadsWhatTheFileHolds) {
  auto file = test::temp_dir() / "scene.lods";
  auto written = test::write_raw_package(file, 40, 0);
  ASSERT_GT(written.pages, 3u);
  ASSERT_GT(written.index_pages, 1u);
  HttpServer server("127.0.0.1", 0, {{"scene.lods", file, written.content_hash.hex(), nullptr}});
  const std::string url = "http://127.0.0.1:" + std::to_string(server.port()) + "/scene.lods";
  auto source = std::make_shared<HttpSource>(url);
  EXPECT_EQ(source->size(), written.bytes);
  EXPECT_EQ(source->etag(), "\"" + written.content_hash.hex() + "\"");
  EXPECT_EQ(source->name(), url);

  package::PackageReader remote(source);
  package::PackageReader local = package::PackageReader::open(file);
  EXPECT_EQ(remote.header().content_hash, written.content_hash);
  ASSERT_EQ(remote.node_count(), 40u);
  for (uint32_t id = 0; id < remote.node_count(); ++id) {  // index pages fetched on demand
    EXPECT_EQ(remote.node(id).page, local.node(id).page);
    EXPECT_EQ(remote.node(id).size, local.node(id).size);
  }
  for (uint32_t p = 0; p < written.pages; ++p) EXPECT_EQ(remote.read_page(p), local.read_page(p));
  remote.verify();
  EXPECT_EQ(source->connections(), 1u);  // one kept-alive connection for everything
  EXPECT_GT(source->requests(), written.pages);

  // Concurrent reads are safe (serialized on the connection).
  std::vector<std::thread> threads;
  std::atomic<int> bad = 0;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (uint32_t p = t; p < written.pages; p += 4)
        if (remote.read_page(p) != local.read_page(p)) ++bad;
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(bad, 0);

  // Out-of-file ranges are refused before any request.
  std::vector<uint8_t> buf(10);
  EXPECT_NE(error_of([&] { source->read(written.bytes - 5, buf); }).find("outside the file"),
            std::string::npos);
}

TEST(HttpSource, DetectsAPackageChangedOnTheServerAndReconnects) {
  auto dir = test::temp_dir();
  auto first = dir / "v1.lods", second = dir / "v2.lods";
  auto w1 = test::write_raw_package(first, 20, 0);
  auto w2 = test::write_raw_package(second, 20, 1);
  ASSERT_NE(w1.content_hash, w2.content_hash);
  auto server = std::make_unique<HttpServer>(
      "127.0.0.1", 0, std::vector<ServedFile>{{"s.lods", first, w1.content_hash.hex(), nullptr}});
  const uint16_t port = server->port();
  const std::string url = "http://127.0.0.1:" + std::to_string(port) + "/s.lods";
  HttpSource source(url);
  std::vector<uint8_t> a(100);
  source.read(64, a);
  // The same content served again (a server restart): the source reconnects and goes on.
  server.reset();
  server = std::make_unique<HttpServer>(
      "127.0.0.1", port, std::vector<ServedFile>{{"s.lods", first, w1.content_hash.hex(), nullptr}});
  std::vector<uint8_t> b(100);
  source.read(64, b);
  EXPECT_EQ(a, b);
  EXPECT_EQ(source.connections(), 2u);
  // Other content under the same URL: If-Range no longer matches, the server answers 200, we refuse.
  server.reset();
  server = std::make_unique<HttpServer>(
      "127.0.0.1", port, std::vector<ServedFile>{{"s.lods", second, w2.content_hash.hex(), nullptr}});
  const std::string err = error_of([&] { source.read(64, b); });
  EXPECT_EQ(err.rfind(url + ": changed on the server", 0), 0u) << err;
}

TEST(HttpSource, ClearErrorsForBadUrlsAndMissingFiles) {
  auto file = test::temp_dir() / "x.lods";
  auto written = test::write_raw_package(file, 4, 0);
  HttpServer server("127.0.0.1", 0, {{"x.lods", file, written.content_hash.hex(), nullptr}});
  const std::string base = "http://127.0.0.1:" + std::to_string(server.port());
  EXPECT_EQ(error_of([] { HttpSource s("ftp://host/x.lods"); }), "ftp://host/x.lods: not an http:// URL");
  EXPECT_NE(error_of([] { HttpSource s("http://127.0.0.1:99999/x"); }).find("malformed URL"),
            std::string::npos);
  EXPECT_NE(error_of([&] { HttpSource s(base + "/missing.lods"); }).find("HEAD answered 404"),
            std::string::npos);
  // Nothing listening: a connect error naming the URL (port 1 is privileged and unused here).
  EXPECT_NE(error_of([] { HttpSource s("http://127.0.0.1:1/x.lods"); }).find("cannot connect"),
            std::string::npos);
}

TEST(HttpSource, ReadsAPackageFromARealNginxAndDetectsAChange) {
  auto root = test::temp_dir();
  auto file = root / "city.lods";
  auto written = test::write_raw_package(file, 30, 3);
  test::Nginx nginx(root);
  const std::string url = "http://127.0.0.1:" + std::to_string(nginx.port()) + "/city.lods";
  auto source = std::make_shared<HttpSource>(url);
  EXPECT_EQ(source->size(), written.bytes);
  EXPECT_FALSE(source->etag().empty());  // nginx's own tag (mtime-size), used for If-Range
  package::PackageReader remote(source);
  package::PackageReader local = package::PackageReader::open(file);
  for (uint32_t id = 0; id < remote.node_count(); ++id)
    EXPECT_EQ(remote.node(id).offset, local.node(id).offset);
  for (uint32_t p = 0; p < written.pages; ++p) EXPECT_EQ(remote.read_page(p), local.read_page(p));
  remote.verify();
  EXPECT_EQ(source->connections(), 1u);
  // The file replaced under nginx (other content, other size): the next read is refused.
  test::write_raw_package(file, 31, 4);
  std::vector<uint8_t> b(100);
  const std::string err = error_of([&] { source->read(64, b); });
  EXPECT_EQ(err.rfind(url + ": changed on the server", 0), 0u) << "[" << err << "]";
}
