// Link emulator: a TCP proxy that shapes each direction with one LinkDirection (token bucket + delay line,
// net/link_model.hpp) shared by every connection through it, as a client's access link is shared: N parallel
// connections together get the link's bandwidth, in the order their bytes reached the bottleneck.
// `lodstream link` runs one; tests and benchmarks put it in front of `lodstream serve` or nginx, so shaping
// is applied exactly once. The bottleneck holds at most one bandwidth-delay product (at least 20 ms) of
// unsent bytes; beyond that the proxy stops reading and TCP's own flow control pushes back on the senders, as
// a router's finite queue does.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "net/link_model.hpp"

namespace lodstream {

class LinkProxy {
 public:
  // Listens on listen_host:listen_port (port 0 picks a free one) and forwards each connection to
  // to_host:to_port. Runs on its own thread until destroyed. Throws lodstream::Error when the address cannot
  // be bound.
  LinkProxy(const std::string& listen_host, uint16_t listen_port, const std::string& to_host,
            uint16_t to_port, const LinkSettings& settings);
  ~LinkProxy();
  LinkProxy(const LinkProxy&) = delete;
  LinkProxy& operator=(const LinkProxy&) = delete;

  uint16_t port() const;  // the port it listens on

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Splits "HOST:PORT" ("[::1]:8080" for IPv6); throws lodstream::Error naming `option` when malformed.
std::pair<std::string, uint16_t> parse_host_port(const std::string& text, const std::string& option);

}  // namespace lodstream
