// HttpSource: a package::ByteSource that reads byte ranges over HTTP/1.1 (DESIGN.md, Serving and the wire:
// pull mode works against any static server), so PackageReader opens "http://127.0.0.1:PORT/NAME.lods" as it
// opens a file. Opening sends one HEAD request (size, ETag or Last-Modified); each read() is one
// `GET Range: bytes=A-B` with `If-Range: <validator>` on one keep-alive connection (reconnected once when the
// server closed it). A server whose file changed answers 200 to If-Range instead of 206: that, a
// Content-Range that does not name the requested bytes and the size seen at open, or a short body, is a
// one-line lodstream::Error naming the URL ("changed on the server" for the first). Every network step has
// a time-out (Options::timeout_s). Thread-safe: reads from several threads are serialized on the one
// connection (a request window of parallel connections is the pull scheduler's business).
// Written on Boost.Beast (no Range client in Beast 1.74 or elsewhere in Debian that fits).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "package/byte_source.hpp"

namespace lodstream {

class HttpSource final : public package::ByteSource {
 public:
  struct Options {
    double timeout_s = 30.0;  // per connect, request or response
  };

  // `url`: "http://HOST[:PORT]/PATH" (no https). Throws lodstream::Error naming the URL when it is malformed,
  // the server cannot be reached, or the HEAD request does not give a length (or answers other than 200).
  explicit HttpSource(const std::string& url, Options options);
  explicit HttpSource(const std::string& url) : HttpSource(url, Options{}) {}
  ~HttpSource() override;
  HttpSource(const HttpSource&) = delete;
  HttpSource& operator=(const HttpSource&) = delete;

  uint64_t size() const override;
  void read(uint64_t offset, std::span<uint8_t> out) const override;
  const std::string& name() const override;

  // The ETag as sent (quotes included, as If-Range needs it), or "" when the server sent none.
  const std::string& etag() const;
  // Requests sent so far (HEAD included) and connections opened.
  uint64_t requests() const;
  uint64_t connections() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lodstream
