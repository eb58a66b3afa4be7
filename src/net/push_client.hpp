// Push transport of a client (DESIGN.md, Serving and the wire): a WebSocket to ws://HOST:PORT/NAME on its own
// thread and io_context. It sends the Hello, receives the Welcome and then pages (left in a PageInbox for the
// frame loop), acknowledges every page as it arrives (cumulatively: the latest sequence, with the page's
// server time echoed), and sends the latest view the frame loop gave it (send_view: the newest replaces one
// not yet sent). A connection lost after a Welcome (the server restarted) is opened again with back-off,
// its Hello listing the pages held at the start plus every page received since, so that the server sends
// none of them again (issue 5); meanwhile the frame loop keeps drawing what it holds. Pages the client's
// cache evicts are said to the server (released()), which may then send them again, or, when the client keeps
// them on disk, send a Restore (left in the inbox as an ArrivedPage with from_disk and no bytes: the frame
// loop loads the page from its disk cache, and says released(page, false) when it cannot). A Bye from the
// server, a malformed message, or a first connection that fails is reported through the inbox.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <thread>

#include "net/page_inbox.hpp"
#include "net/wire.hpp"

namespace lodstream {

struct PushReconnect {
  bool enabled = true;
  double first_backoff_s = 0.1;  // the wait before the first attempt; doubles per failed attempt
  double max_backoff_s = 2.0;
};

class PushClient {
 public:
  // `url`: ws://HOST:PORT/NAME. Returns at once; connecting happens on the client's thread (a failure is
  // reported through `inbox`). Throws lodstream::Error when the URL is malformed. `inbox` must outlive this.
  PushClient(const std::string& url, wire::Hello hello, PageInbox& inbox, PushReconnect reconnect = {});
  // The same, but the Hello is not known yet (a client with a disk cache must read the package's root index
  // to list what it holds): the TCP connection and the WebSocket handshake go ahead at once, and the Hello
  // goes out when say_hello() gives it.
  PushClient(const std::string& url, PageInbox& inbox, PushReconnect reconnect = {});
  ~PushClient();  // closes the WebSocket (a normal close) and joins the thread
  PushClient(const PushClient&) = delete;
  PushClient& operator=(const PushClient&) = delete;

  // The Hello of a client constructed without one (call once; before it, nothing is sent).
  void say_hello(wire::Hello hello);

  void send_view(const wire::ViewUpdate& view);
  // Data pages the client's memory cache evicted: said to the server (a Released message) so that it may send
  // them again, and left out of a reconnection's Hello. `on_disk`: the client's disk cache keeps them (the
  // server may send a Restore instead of the bytes; a reconnection's Hello lists them as on disk); without
  // it they are gone (also what a Restore that could not be loaded is said with).
  void released(std::span<const uint32_t> pages, bool on_disk = false);
  bool welcomed() const { return welcomed_; }
  uint64_t pages_received() const { return pages_; }
  // Connections opened again (and welcomed) after one was lost.
  uint64_t reconnects() const { return reconnects_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<bool> welcomed_{false};
  std::atomic<uint64_t> pages_{0}, reconnects_{0};
  std::thread thread_;
};

}  // namespace lodstream
