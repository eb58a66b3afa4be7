// A push session (DESIGN.md, Serving and the wire): one client on a WebSocket at "/NAME". The client says
// hello (package, the content hash of what it caches, the pages it holds, its budget and viewport) and then
// sends view updates and acknowledgements; the server answers with a welcome and then pushes pages, never one
// the client holds, keeping about two estimated bandwidth-delay products in flight (schedule::LinkEstimator
// fed by the acknowledgements) and TCP_NOTSENT_LOWAT on the socket, so that little waits in the kernel and a
// new order takes effect within about a round trip.
//
// Page order: for now, file order (coarse levels first, as the baker lays pages out) — the order of
// DESIGN.md's `full` baseline. The view-dependent, benefit-per-byte scheduler (schedule module) replaces
// PageOrder.
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

#include "package/reader.hpp"

namespace lodstream {

struct PushOptions {
  double ack_timeout_s = 30.0;
  size_t min_window_bytes = 64 * 1024;  // in flight at least this much, before the first estimates
  int notsent_lowat_bytes = 16 * 1024;  // TCP_NOTSENT_LOWAT
};

struct PushStats {
  uint64_t pages_sent = 0, bytes_sent = 0, views = 0, acks = 0;
  std::string end_reason;
};

using WebSocket = boost::beast::websocket::stream<boost::beast::tcp_stream>;

// Runs one session on an accepted WebSocket for package `name`, read through `package` (both must outlive
// the session). Returns when the session ends (everything sent and acknowledged and the client closed, or an
// error); never throws.
boost::asio::awaitable<PushStats> run_push_session(WebSocket& ws, const std::string& name,
                                                   const package::PackageReader& package,
                                                   PushOptions options = {});

}  // namespace lodstream
