#include "net/http_server.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cstdio>
#include <thread>

#include "core/error.hpp"
#include "net/http_range.hpp"
#include "net/push_session.hpp"

namespace lodstream {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using asio::awaitable;
using asio::use_awaitable;
using asio::ip::tcp;

namespace {

constexpr size_t kChunk = 64 * 1024;
constexpr auto kTimeout =
    std::chrono::seconds(30);  // a client that sends or reads nothing this long is dropped

struct OpenFile {
  ServedFile served;
  int fd = -1;
  uint64_t size = 0;
  std::shared_ptr<const PushPackage> push;  // its push stream's package (records loaded once), or null
};

// A response body: literal strings and ranges of the file, sent in order.
struct Piece {
  std::string text;
  ByteRange range{};
  bool is_range = false;
};

// The log line of an ended push session.
std::string session_line(const std::string& name, const PushStats& stats) {
  const PushCounters& c = stats.counters;
  return "push session for " + name + ": " + std::to_string(c.pages_sent) + " pages (" +
         std::to_string(c.index_pages_sent) + " index, " + std::to_string(c.restores) +
         " restored from the client's disk), " + std::to_string(c.bytes_sent) + " bytes, " +
         std::to_string(c.views) + " views, " + std::to_string(c.acks) + " acks; " + stats.end_reason;
}

}  // namespace

struct HttpServer::Impl {
  asio::io_context io;
  tcp::acceptor acceptor{io};
  std::vector<OpenFile> files;
  std::vector<std::thread> threads;
  std::atomic<uint64_t> next_connection{1};

  ~Impl() {
    for (auto& f : files)
      if (f.fd >= 0) close(f.fd);
  }

  const OpenFile* find(std::string_view target) const {
    target = target.substr(0, target.find('?'));
    for (const auto& f : files)
      if (target.size() == f.served.name.size() + 1 && target[0] == '/' && target.substr(1) == f.served.name)
        return &f;
    return nullptr;
  }

  awaitable<void> accept_loop() {
    for (;;) {
      tcp::socket socket(asio::make_strand(io));
      co_await acceptor.async_accept(socket, use_awaitable);
      // Answers are written whole; Nagle would hold a short final segment back by up to an ACK delay (~40
      // ms).
      boost::system::error_code ec;
      socket.set_option(tcp::no_delay(true), ec);
      asio::co_spawn(socket.get_executor(), session(std::move(socket)), asio::detached);
    }
  }

  awaitable<void> session(tcp::socket socket) {
    const uint64_t id = next_connection++;
    std::string peer = "?";
    boost::system::error_code ec;
    auto remote = socket.remote_endpoint(ec);
    if (!ec) peer = remote.address().to_string() + ":" + std::to_string(remote.port());
    std::fprintf(stderr, "serve: connection %llu from %s opened\n", (unsigned long long)id, peer.c_str());
    beast::tcp_stream stream(std::move(socket));
    beast::flat_buffer buffer;
    uint64_t requests = 0, sent = 0;
    std::string reason = "closed by client";
    try {
      for (;;) {
        http::request_parser<http::empty_body> parser;
        parser.header_limit(16 * 1024);
        stream.expires_after(kTimeout);
        co_await http::async_read(stream, buffer, parser, use_awaitable);
        ++requests;
        const auto& request = parser.get();
        if (beast::websocket::is_upgrade(request)) {
          reason = co_await push(std::move(stream), request);
          break;
        }
        sent += co_await respond(stream, request);
        if (!request.keep_alive()) {
          reason = "done";
          break;
        }
      }
    } catch (const boost::system::system_error& e) {
      if (e.code() != http::error::end_of_stream) reason = e.code().message();
    }
    if (stream.socket().is_open()) stream.socket().shutdown(tcp::socket::shutdown_send, ec);
    std::fprintf(stderr, "serve: connection %llu from %s closed after %llu requests, %llu bytes (%s)\n",
                 (unsigned long long)id, peer.c_str(), (unsigned long long)requests, (unsigned long long)sent,
                 reason.c_str());
  }

  // Turns the connection into a push session for the package named by the target ("/NAME"); returns how the
  // session ended.
  awaitable<std::string> push(beast::tcp_stream stream, const http::request<http::empty_body>& request) {
    std::string_view target(request.target().data(), request.target().size());
    const OpenFile* file = nullptr;
    for (const auto& f : files)
      if (f.push && target.size() > 1 && target[0] == '/' &&
          std::string(target.substr(1)) + ".lods" == f.served.name)
        file = &f;
    if (!file) {
      http::response<http::string_body> response{http::status::not_found, request.version()};
      response.body() = "no push stream at this address\n";
      response.prepare_payload();
      co_await http::async_write(stream, response, use_awaitable);
      co_return "no push stream at " + std::string(target);
    }
    stream.expires_never();  // the WebSocket keeps its own time-outs
    WebSocket ws(std::move(stream));
    co_await ws.async_accept(request, use_awaitable);
    const PushOptions
        options;  // (constructed outside the co_await: GCC 12 rejects its default argument there)
    PushStats stats = co_await run_push_session(ws, file->push, options);
    co_return session_line(file->push->name, stats);
  }

  // Answers one request; returns the body bytes sent.
  awaitable<uint64_t> respond(beast::tcp_stream& stream, const http::request<http::empty_body>& request) {
    http::response<http::empty_body> response{http::status::ok, request.version()};
    response.set(http::field::server, "lodstream");
    response.keep_alive(request.keep_alive());
    std::vector<Piece> body;
    const OpenFile* file = nullptr;
    if (request.method() != http::verb::get && request.method() != http::verb::head) {
      response.result(http::status::method_not_allowed);
      response.set(http::field::allow, "GET, HEAD");
      body.push_back({"only GET and HEAD are served\n"});
    } else if (!(file = find(std::string_view(request.target().data(), request.target().size())))) {
      response.result(http::status::not_found);
      body.push_back({"no such package\n"});
    } else {
      const std::string etag = "\"" + file->served.etag + "\"";
      response.set(http::field::etag, etag);
      response.set(http::field::accept_ranges, "bytes");
      auto if_none_match = request[http::field::if_none_match];
      auto range_header = request[http::field::range];
      auto if_range = request[http::field::if_range];
      // If-Range with anything but the current strong tag (an old tag, a date) means: send everything.
      bool use_range = !range_header.empty() && (if_range.empty() || if_range == etag);
      RangeRequest ranges =
          use_range ? parse_range(std::string_view(range_header.data(), range_header.size()), file->size)
                    : RangeRequest{};
      if (!if_none_match.empty() && (if_none_match == etag || if_none_match == "*")) {
        response.result(http::status::not_modified);
      } else if (ranges.kind == RangeRequest::Kind::kUnsatisfiable) {
        response.result(http::status::range_not_satisfiable);
        response.set(http::field::content_range, "bytes */" + std::to_string(file->size));
      } else if (ranges.kind == RangeRequest::Kind::kSatisfiable && ranges.ranges.size() == 1) {
        response.result(http::status::partial_content);
        response.set(http::field::content_range, content_range(ranges.ranges[0], file->size));
        response.set(http::field::content_type, "application/octet-stream");
        body.push_back({{}, ranges.ranges[0], true});
      } else if (ranges.kind == RangeRequest::Kind::kSatisfiable) {
        const std::string boundary = "lodstream-" + file->served.etag.substr(0, 16);
        response.result(http::status::partial_content);
        response.set(http::field::content_type, "multipart/byteranges; boundary=" + boundary);
        for (const auto& r : ranges.ranges) {
          body.push_back({"\r\n--" + boundary +
                          "\r\nContent-Type: application/octet-stream\r\nContent-Range: " +
                          content_range(r, file->size) + "\r\n\r\n"});
          body.push_back({{}, r, true});
        }
        body.push_back({"\r\n--" + boundary + "--\r\n"});
      } else {
        response.set(http::field::content_type, "application/octet-stream");
        if (file->size > 0) body.push_back({{}, ByteRange{0, file->size - 1}, true});
      }
    }
    uint64_t length = 0;
    for (const auto& p : body) length += p.is_range ? p.range.size() : p.text.size();
    if (response.result() != http::status::not_modified)
      response.set(http::field::content_length, std::to_string(length));
    http::response_serializer<http::empty_body> serializer{response};
    stream.expires_after(kTimeout);
    co_await http::async_write_header(stream, serializer, use_awaitable);
    if (request.method() == http::verb::head || response.result() == http::status::not_modified) co_return 0;
    std::vector<char> chunk;
    for (const auto& p : body) {
      if (!p.is_range) {
        stream.expires_after(kTimeout);
        co_await asio::async_write(stream, asio::buffer(p.text), use_awaitable);
        continue;
      }
      chunk.resize(kChunk);
      for (uint64_t at = p.range.first; at <= p.range.last;) {
        size_t n = size_t(std::min<uint64_t>(kChunk, p.range.last - at + 1));
        ssize_t got = pread(file->fd, chunk.data(), n, off_t(at));
        if (got != ssize_t(n))
          throw boost::system::system_error(asio::error::broken_pipe);  // the file shrank
        stream.expires_after(kTimeout);
        co_await asio::async_write(stream, asio::buffer(chunk.data(), n), use_awaitable);
        at += n;
      }
    }
    co_return length;
  }
};

HttpServer::HttpServer(const std::string& host, uint16_t port, std::vector<ServedFile> files, int threads)
    : impl_(std::make_unique<Impl>()) {
  for (auto& served : files) {
    OpenFile f{std::move(served), -1, 0, nullptr};
    f.fd = open(f.served.path.c_str(), O_RDONLY | O_CLOEXEC);
    if (f.fd < 0) throw Error(f.served.path.string() + ": cannot open for serving");
    f.size = std::filesystem::file_size(f.served.path);
    impl_->files.push_back(std::move(f));
    OpenFile& added = impl_->files.back();
    if (added.served.package) {
      const std::string& name = added.served.name;
      const bool lods = name.size() > 5 && name.ends_with(".lods");
      added.push = std::make_shared<const PushPackage>(lods ? name.substr(0, name.size() - 5) : name,
                                                       added.served.package);
    }
  }
  boost::system::error_code ec;
  auto address = asio::ip::make_address(host, ec);
  if (ec) throw Error("--bind: '" + host + "' is not an IP address");
  tcp::endpoint endpoint(address, port);
  impl_->acceptor.open(endpoint.protocol(), ec);
  if (!ec) impl_->acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) impl_->acceptor.bind(endpoint, ec);
  if (!ec) impl_->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) throw Error("cannot listen on " + host + ":" + std::to_string(port) + ": " + ec.message());
  asio::co_spawn(impl_->io, impl_->accept_loop(), asio::detached);
  for (int i = 0; i < std::max(1, threads); ++i) impl_->threads.emplace_back([this] { impl_->io.run(); });
}

HttpServer::~HttpServer() {
  impl_->io.stop();
  for (auto& t : impl_->threads) t.join();
}

uint16_t HttpServer::port() const {
  return impl_->acceptor.local_endpoint().port();
}

}  // namespace lodstream
