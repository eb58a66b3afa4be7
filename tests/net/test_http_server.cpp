#include <gtest/gtest.h>

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <fstream>

#include "core/error.hpp"
#include "net/http_server.hpp"
#include "support/run.hpp"

using namespace lodstream;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using asio::ip::tcp;

namespace {
struct HttpServerTest : ::testing::Test {
  std::string content;
  std::unique_ptr<HttpServer> server;
  asio::io_context io;
  beast::tcp_stream stream{io};

  void SetUp() override {
    for (int i = 0; i < 300000; ++i) content.push_back(char('a' + (i * 7) % 26));
    auto path = test::temp_dir() / "scene.lods";
    std::ofstream(path, std::ios::binary) << content;
    server = std::make_unique<HttpServer>("127.0.0.1", 0,
                                          std::vector<ServedFile>{{"scene.lods", path, "abc123", nullptr}});
    stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), server->port()));
  }

  http::response<http::string_body> get(const std::string& target,
                                        std::vector<std::pair<http::field, std::string>> fields = {},
                                        http::verb verb = http::verb::get) {
    http::request<http::empty_body> req{verb, target, 11};
    req.set(http::field::host, "127.0.0.1");
    for (auto& [f, v] : fields) req.set(f, v);
    http::write(stream, req);
    beast::flat_buffer buffer;
    http::response_parser<http::string_body> parser;
    parser.body_limit(10'000'000);
    if (verb == http::verb::head) parser.skip(true);
    http::read(stream, buffer, parser);
    return parser.release();
  }
};
}  // namespace

TEST_F(HttpServerTest, WholeFileWithEtagAndAcceptRanges) {
  auto r = get("/scene.lods");
  EXPECT_EQ(r.result(), http::status::ok);
  EXPECT_EQ(r.body(), content);
  EXPECT_EQ(r[http::field::etag], "\"abc123\"");
  EXPECT_EQ(r[http::field::accept_ranges], "bytes");
  // Keep-alive: a second request on the same connection.
  auto h = get("/scene.lods", {}, http::verb::head);
  EXPECT_EQ(h.result(), http::status::ok);
  EXPECT_EQ(h[http::field::content_length], std::to_string(content.size()));
}

TEST_F(HttpServerTest, SingleAndSuffixRanges) {
  auto r = get("/scene.lods", {{http::field::range, "bytes=1000-1999"}});
  EXPECT_EQ(r.result(), http::status::partial_content);
  EXPECT_EQ(r.body(), content.substr(1000, 1000));
  EXPECT_EQ(r[http::field::content_range], "bytes 1000-1999/300000");
  r = get("/scene.lods", {{http::field::range, "bytes=-10"}});
  EXPECT_EQ(r.body(), content.substr(content.size() - 10));
  r = get("/scene.lods", {{http::field::range, "bytes=200000-"}});
  EXPECT_EQ(r.body(), content.substr(200000));  // spans several 64 KB pieces
}

TEST_F(HttpServerTest, MultipleRangesAsMultipart) {
  auto r = get("/scene.lods", {{http::field::range, "bytes=0-9,100-109"}});
  EXPECT_EQ(r.result(), http::status::partial_content);
  std::string type(r[http::field::content_type]);
  ASSERT_EQ(type.rfind("multipart/byteranges; boundary=", 0), 0u) << type;
  std::string boundary = type.substr(type.find('=') + 1);
  const std::string& b = r.body();
  size_t first = b.find("Content-Range: bytes 0-9/300000\r\n\r\n");
  size_t second = b.find("Content-Range: bytes 100-109/300000\r\n\r\n");
  ASSERT_NE(first, std::string::npos);
  ASSERT_NE(second, std::string::npos);
  EXPECT_EQ(b.substr(first + 35, 10), content.substr(0, 10));
  EXPECT_EQ(b.substr(second + 39, 10), content.substr(100, 10));
  EXPECT_NE(b.find("--" + boundary + "--"), std::string::npos);
}

TEST_F(HttpServerTest, UnsatisfiableIfRangeAndConditional) {
  auto r = get("/scene.lods", {{http::field::range, "bytes=400000-"}});
  EXPECT_EQ(r.result(), http::status::range_not_satisfiable);
  EXPECT_EQ(r[http::field::content_range], "bytes */300000");
  // If-Range with a stale tag: the whole file, not the range.
  r = get("/scene.lods", {{http::field::range, "bytes=0-9"}, {http::field::if_range, "\"old\""}});
  EXPECT_EQ(r.result(), http::status::ok);
  EXPECT_EQ(r.body().size(), content.size());
  r = get("/scene.lods", {{http::field::range, "bytes=0-9"}, {http::field::if_range, "\"abc123\""}});
  EXPECT_EQ(r.result(), http::status::partial_content);
  r = get("/scene.lods", {{http::field::if_none_match, "\"abc123\""}});
  EXPECT_EQ(r.result(), http::status::not_modified);
  EXPECT_TRUE(r.body().empty());
}

TEST_F(HttpServerTest, ErrorsForOtherPathsAndMethods) {
  EXPECT_EQ(get("/other.lods").result(), http::status::not_found);
  EXPECT_EQ(get("/scene.lods/../x").result(), http::status::not_found);
  EXPECT_EQ(get("/scene.lods", {}, http::verb::delete_).result(), http::status::method_not_allowed);
}

TEST_F(HttpServerTest, GarbageOnOneConnectionDoesNotAffectAnother) {
  // A connection that sends garbage and an oversized header is dropped...
  beast::tcp_stream bad{io};
  bad.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), server->port()));
  std::string junk = "GARBAGE \x01\x02 HTTP/9\r\n" + std::string(40000, 'x') + "\r\n\r\n";
  boost::system::error_code ec;
  asio::write(bad, asio::buffer(junk), ec);
  char c;
  bad.socket().read_some(asio::buffer(&c, 1), ec);
  EXPECT_TRUE(ec) << "the server kept a garbage connection open";
  // ...while this one still works.
  EXPECT_EQ(get("/scene.lods", {{http::field::range, "bytes=0-0"}}).body(), content.substr(0, 1));
}

TEST(HttpServer, MissingFileAndBadAddressAreErrors) {
  EXPECT_THROW(HttpServer("127.0.0.1", 0, {{"x.lods", "/nonexistent/x.lods", "1", nullptr}}), Error);
  EXPECT_THROW(HttpServer("localhost", 0, {}), Error);
}
