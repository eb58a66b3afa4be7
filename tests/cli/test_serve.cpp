#include <gtest/gtest.h>

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <fstream>

#include "package/reader.hpp"
#include "package/writer.hpp"
#include "support/run.hpp"

using namespace lodstream;
namespace http = boost::beast::http;

namespace {
std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Sends one GET over a new connection and returns the response.
http::response<http::string_body> get(uint16_t port, const std::string& target,
                                      const std::string& range = "") {
  boost::asio::io_context io;
  boost::beast::tcp_stream stream(io);
  stream.connect({boost::asio::ip::make_address("127.0.0.1"), port});
  http::request<http::empty_body> req{http::verb::get, target, 11};
  req.set(http::field::host, "127.0.0.1");
  if (!range.empty()) req.set(http::field::range, range);
  http::write(stream, req);
  boost::beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(stream, buffer, res);
  return res;
}
}  // namespace

TEST(Serve, ServesAPackageWithRangesAndStopsOnSigterm) {
  auto dir = test::temp_dir();
  auto file = dir / "tiny.lods";
  package::PackageWriter(file).finish({}, {}, 0);
  std::string bytes = slurp(file);
  ASSERT_GT(bytes.size(), 16u);
  std::string etag = "\"" + package::PackageReader::open(file).header().content_hash.hex() + "\"";

  test::BackgroundProcess server({"serve", file.string(), "--port", "0"});
  std::string line = server.read_line();
  ASSERT_EQ(line.rfind("listening on http://127.0.0.1:", 0), 0u) << line;
  uint16_t port = uint16_t(std::stoi(line.substr(line.rfind(':') + 1)));

  auto whole = get(port, "/tiny.lods");
  EXPECT_EQ(whole.result(), http::status::ok);
  EXPECT_EQ(whole.body(), bytes);
  EXPECT_EQ(whole[http::field::etag], etag);
  auto part = get(port, "/tiny.lods", "bytes=4-11");
  EXPECT_EQ(part.result(), http::status::partial_content);
  EXPECT_EQ(part.body(), bytes.substr(4, 8));
  EXPECT_EQ(get(port, "/tiny").result(), http::status::not_found);
  EXPECT_EQ(server.stop(), 0);
}

TEST(Serve, RefusesFilesThatAreNotPackages) {
  auto dir = test::temp_dir();
  std::ofstream(dir / "fake.lods") << "this is not a package";
  auto r = test::run_lodstream({"serve", (dir / "fake.lods").string(), "--port", "0"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("lodstream: error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("fake.lods"), std::string::npos) << r.err;
  r = test::run_lodstream({"serve", (dir / "missing.lods").string()});
  EXPECT_EQ(r.status, 1);
  r = test::run_lodstream({"serve", (dir / "fake.lods").string(), "--port", "70000"});
  EXPECT_EQ(r.status, 1);
}
