// A push session (DESIGN.md, Serving and the wire): one client on a WebSocket at "/NAME". The protocol itself
// (hello, welcome, views, acknowledgements, which page goes next, the window, time-outs) is
// net/push_protocol.hpp's sans-I/O state machine; this is its asio shell: a reader coroutine feeds it the
// client's messages, the writer sends what it asks for and waits for an acknowledgement, a new view or its
// acknowledgement deadline. TCP_NOTSENT_LOWAT on the socket keeps the kernel's unsent queue short, so that
// what waits, waits in the protocol, where a new view re-orders it within about a round trip.
//
// A malformed, oversized or out-of-order message, or a client that acknowledges nothing for `ack_timeout_s`
// while pages are in flight, ends this session with a Bye naming the reason; other sessions are unaffected.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <boost/asio/awaitable.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/websocket/stream.hpp>

#include "net/push_protocol.hpp"

namespace lodstream {

struct PushOptions {
  PushProtocolOptions protocol;
  int notsent_lowat_bytes = 16 * 1024;  // TCP_NOTSENT_LOWAT
};

struct PushStats {
  PushCounters counters;
  std::string end_reason;
};

using WebSocket = boost::beast::websocket::stream<boost::beast::tcp_stream>;

// Runs one session on an accepted WebSocket for `package`. Returns when the session ends (the client closed
// or said bye, or an error); never throws.
boost::asio::awaitable<PushStats> run_push_session(WebSocket& ws, std::shared_ptr<const PushPackage> package,
                                                   PushOptions options = {});

}  // namespace lodstream
