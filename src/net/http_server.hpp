// HTTP server for packages (DESIGN.md, Serving and the wire): serves each file at "/NAME.lods" with byte
// ranges (single, suffix and multiple: multipart/byteranges; 416 when unsatisfiable), a strong ETag (the
// package's content hash), If-Range and If-None-Match, GET and HEAD, HTTP/1.1 keep-alive. Bodies are streamed
// from the file in 64 KB pieces, so memory per client stays small whatever is asked for. One line is logged
// to standard error per connection start and end. Hostile requests (huge headers, bodies, bad methods or
// paths) get an HTTP error or a closed connection, never affecting other connections. A WebSocket upgrade at
// "/NAME" starts a push session for that package (net/push_session.hpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "package/reader.hpp"

namespace lodstream {

struct ServedFile {
  std::string name;            // served at "/" + name (for example "city.lods")
  std::filesystem::path path;  // the file; it must not change while served
  std::string etag;            // strong entity tag without quotes (the package's content hash in hex)
  // When set, the package's push stream is a WebSocket at "/" + name without ".lods" (net/push_session.hpp).
  std::shared_ptr<const package::PackageReader> package;
};

class HttpServer {
 public:
  // Binds host:port (port 0 picks a free one) and serves `files` on `threads` threads until destroyed.
  // Throws lodstream::Error when the address cannot be bound or a file cannot be opened.
  HttpServer(const std::string& host, uint16_t port, std::vector<ServedFile> files, int threads = 2);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  uint16_t port() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lodstream
