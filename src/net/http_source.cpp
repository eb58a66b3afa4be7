#include "net/http_source.hpp"

#include "net/url.hpp"

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <charconv>
#include <chrono>
#include <cstring>
#include <limits>
#include <mutex>
#include <optional>

#include "core/error.hpp"

namespace lodstream {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using asio::ip::tcp;

struct HttpSource::Impl {
  std::string url, host, port, target;
  Options options;
  uint64_t size = 0;
  std::string etag, validator;  // validator: ETag (strong) or Last-Modified, sent as If-Range
  uint64_t requests = 0, connections = 0;

  std::mutex mutex;
  asio::io_context io;
  std::optional<beast::tcp_stream> stream;
  beast::flat_buffer buffer;

  [[noreturn]] void fail(const std::string& what) const { throw Error(url + ": " + what); }

  std::chrono::steady_clock::duration timeout() const {
    return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(options.timeout_s));
  }

  // Runs the asynchronous operation started by `start` (which reports into `ec`) to completion; the
  // stream's expiry (expires_after) bounds it.
  template <class Start>
  beast::error_code run(Start start) {
    beast::error_code ec = asio::error::would_block;
    start(ec);
    io.restart();
    io.run();
    return ec;
  }

  void connect() {
    stream.reset();
    buffer.clear();
    tcp::resolver resolver(io);
    tcp::resolver::results_type endpoints;
    beast::error_code ec = run([&](beast::error_code& out) {
      resolver.async_resolve(host, port, [&](beast::error_code e, tcp::resolver::results_type r) {
        out = e;
        endpoints = std::move(r);
      });
    });
    if (ec) fail("cannot resolve " + host + ": " + ec.message());
    stream.emplace(io);
    stream->expires_after(timeout());
    ec = run([&](beast::error_code& out) {
      stream->async_connect(endpoints, [&](beast::error_code e, const tcp::endpoint&) { out = e; });
    });
    if (ec) {
      stream.reset();
      fail("cannot connect: " + ec.message());
    }
    stream->socket().set_option(tcp::no_delay(true), ec);  // one write per request; no Nagle delay
    ++connections;
  }

  // Sends `req` and reads the response header into `parser`. Reconnects and retries once when a kept-alive
  // connection turns out closed. Returns false (nothing thrown) only for that first failure.
  template <class Parser>
  bool exchange(http::request<http::empty_body>& req, Parser& parser, bool retry) {
    if (!stream) connect();
    ++requests;
    stream->expires_after(timeout());
    beast::error_code ec = run([&](beast::error_code& out) {
      http::async_write(*stream, req, [&](beast::error_code e, size_t) { out = e; });
    });
    if (!ec) {
      stream->expires_after(timeout());
      ec = run([&](beast::error_code& out) {
        http::async_read_header(*stream, buffer, parser, [&](beast::error_code e, size_t) { out = e; });
      });
    }
    if (!ec) return true;
    stream.reset();
    if (retry && (ec == http::error::end_of_stream || ec == asio::error::connection_reset ||
                  ec == asio::error::broken_pipe || ec == asio::error::eof))
      return false;
    fail("request failed: " + ec.message());
  }

  template <class Parser>
  void request(http::request<http::empty_body>& req, Parser& make_parser) {
    for (bool retry : {true, false}) {
      auto& parser = make_parser();
      if (exchange(req, parser, retry)) return;
    }
  }

  http::request<http::empty_body> make_request(http::verb verb) const {
    http::request<http::empty_body> req{verb, target, 11};
    req.set(http::field::host, host + ":" + port);
    req.set(http::field::user_agent, "lodstream");
    req.keep_alive(true);
    return req;
  }

  void head() {
    auto req = make_request(http::verb::head);
    std::optional<http::response_parser<http::empty_body>> parser;
    auto make = [&]() -> auto& {
      parser.emplace();
      parser->skip(true);
      return *parser;
    };
    request(req, make);
    const auto& res = parser->get();
    if (res.result() != http::status::ok)
      fail("HEAD answered " + std::to_string(res.result_int()) + " " + std::string(res.reason()));
    if (!parser->content_length()) fail("HEAD gave no Content-Length");
    size = *parser->content_length();
    etag = std::string(res[http::field::etag]);
    if (!etag.empty() && etag.rfind("W/", 0) != 0)
      validator = etag;  // If-Range needs a strong validator
    else
      validator = std::string(res[http::field::last_modified]);
    if (!res.keep_alive()) stream.reset();
  }

  void get(uint64_t offset, std::span<uint8_t> out) {
    auto req = make_request(http::verb::get);
    const uint64_t last = offset + out.size() - 1;
    const std::string range = std::to_string(offset) + "-" + std::to_string(last);
    req.set(http::field::range, "bytes=" + range);
    if (!validator.empty()) req.set(http::field::if_range, validator);
    std::optional<http::response_parser<http::vector_body<uint8_t>>> parser;
    auto make = [&]() -> auto& {
      parser.emplace();
      parser->body_limit(std::numeric_limits<uint64_t>::max());  // checked below, once the status is known
      return *parser;
    };
    request(req, make);
    const auto& res = parser->get();
    if (res.result() != http::status::partial_content) {
      stream.reset();  // do not read a whole-file body we did not ask for
      if (res.result() == http::status::ok)
        fail("changed on the server (If-Range " + validator +
             " no longer matches: " + std::string(res[http::field::etag]) + ")");
      fail("range " + range + " answered " + std::to_string(res.result_int()) + " " +
           std::string(res.reason()));
    }
    const std::string expected = "bytes " + range + "/" + std::to_string(size);
    if (res[http::field::content_range] != expected) {
      stream.reset();
      fail("Content-Range '" + std::string(res[http::field::content_range]) + "' instead of '" + expected +
           "' (the file changed size on the server, or the server ignored the range)");
    }
    if (parser->content_length() != out.size()) {
      stream.reset();
      fail("range " + range + " announced a body of another size");
    }
    stream->expires_after(timeout());
    beast::error_code ec = run([&](beast::error_code& o) {
      http::async_read(*stream, buffer, *parser, [&](beast::error_code e, size_t) { o = e; });
    });
    if (ec) {
      stream.reset();
      fail("reading range " + range + ": " + ec.message());
    }
    const auto& body = parser->get().body();
    if (body.size() != out.size()) {
      stream.reset();
      fail("range " + range + " returned " + std::to_string(body.size()) + " bytes");
    }
    std::memcpy(out.data(), body.data(), out.size());
    if (!parser->get().keep_alive()) stream.reset();
  }
};

HttpSource::HttpSource(const std::string& url, Options options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.url = url;
  m.options = options;
  UrlParts parts = split_url(url, "http://");
  m.host = std::move(parts.host);
  m.port = std::move(parts.port);
  m.target = std::move(parts.target);
  m.head();
}

HttpSource::~HttpSource() = default;

uint64_t HttpSource::size() const {
  return impl_->size;
}
const std::string& HttpSource::name() const {
  return impl_->url;
}
const std::string& HttpSource::etag() const {
  return impl_->etag;
}

uint64_t HttpSource::requests() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->requests;
}

uint64_t HttpSource::connections() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->connections;
}

void HttpSource::read(uint64_t offset, std::span<uint8_t> out) const {
  if (offset > impl_->size || out.size() > impl_->size - offset)
    impl_->fail("range [" + std::to_string(offset) + ", +" + std::to_string(out.size()) +
                ") is outside the file (" + std::to_string(impl_->size) + " bytes)");
  if (out.empty()) return;
  std::lock_guard lock(impl_->mutex);
  impl_->get(offset, out);
}

}  // namespace lodstream
